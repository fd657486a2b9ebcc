#!/usr/bin/env python3
"""The report's sampling noise at each spp, against a reference run (make bench; docs/report-noise.md).

usage: report_noise.py FACETFIT OUT.md [SOURCE] [SPP,...] [REFERENCE_SPP]

Runs `facetfit report` on SOURCE (default builtin:) once per spp and once at REFERENCE_SPP (default 1024),
all from one bake cache, and writes how far each run's Delta E lies from the reference's: per material and
representation (mean and largest |difference|), and per representation for the database means the report
ranks. Noise is what the report's ranking must stand above: the gaps between consecutive database means
are printed beside it.
"""
import json
import os
import statistics
import subprocess
import sys
import tempfile


def report(facetfit, source, spp, folder, luts):
    subprocess.run([facetfit, "report", source, "--spp", str(spp), "-o", folder, "--luts", luts],
                   stdout=subprocess.DEVNULL, check=True)
    with open(os.path.join(folder, "report.json")) as f:
        return json.load(f)


def per_entry(data):
    return {(m["name"], rep): value for m in data["materials"] for rep, value in m["delta_e"].items()}


def gaps(means):
    """Each representation's database mean above the next better one's, in the report's order."""
    ranked = sorted(means.items(), key=lambda kv: kv[1])
    return [(a, b, vb - va) for (a, va), (b, vb) in zip(ranked, ranked[1:])]


def main():
    facetfit, out = sys.argv[1], sys.argv[2]
    source = sys.argv[3] if len(sys.argv) > 3 else "builtin:"
    spps = [int(s) for s in (sys.argv[4] if len(sys.argv) > 4 else "32,256").split(",")]
    reference_spp = int(sys.argv[5]) if len(sys.argv) > 5 else 1024
    with tempfile.TemporaryDirectory() as tmp:
        luts = os.path.join(tmp, "luts")
        reference = report(facetfit, source, reference_spp, os.path.join(tmp, "reference"), luts)
        runs = {spp: report(facetfit, source, spp, os.path.join(tmp, str(spp)), luts) for spp in spps}
    ref_entries, ref_means = per_entry(reference), reference["database_mean_delta_e"]
    lines = [
        "# The report's sampling noise",
        "",
        f"`bench/report_noise.py` (make bench): `facetfit report {source}` at each spp against {reference_spp} spp,",
        "from one bake cache, on this machine. A material's Delta E is the mean over its image; the database",
        "means are what the report ranks representations by.",
        "",
        f"Database means at {reference_spp} spp, best first, and the gap to the next: " +
        "; ".join(f"{a} {ref_means[a]:.3f} to {b} {ref_means[b]:.3f}: {gap:.3f}" for a, b, gap in gaps(ref_means)) + ".",
        "",
        "| spp | material x representation: mean abs. difference | largest | database means: largest abs. difference |",
        "|---|---|---|---|",
    ]
    for spp, data in runs.items():
        entries = per_entry(data)
        diffs = [abs(entries[k] - ref_entries[k]) for k in ref_entries if k in entries]
        mean_diffs = [abs(data["database_mean_delta_e"][r] - ref_means[r]) for r in ref_means]
        lines.append(f"| {spp} | {statistics.mean(diffs):.3f} | {max(diffs):.3f} | {max(mean_diffs):.3f} |")
    with open(out, "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
