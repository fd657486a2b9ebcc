#!/usr/bin/env python3
"""farm.py FACETFIT [REPEATS]: wall time of the built-in report as one process and as `--farm local` with 1
and 3 shards (docs/farm.md, "Speed-up on this machine"). Medians over REPEATS runs (default 3), each into
a fresh folder, printed as a Markdown table with the ratios to the single process.
"""
import statistics
import subprocess
import sys
import tempfile
import time

SETTINGS = ["--refine", "none", "--size", "32", "--spp", "4"]


def seconds(command):
    with tempfile.TemporaryDirectory() as out:
        t0 = time.perf_counter()
        subprocess.run(command + ["-o", out], check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        return time.perf_counter() - t0


def main(facetfit, repeats=3):
    runs = {
        "one process": [facetfit, "-q", "report", *SETTINGS],
        "--farm local, 1 shard": [facetfit, "-q", "report", *SETTINGS, "--farm", "local", "--shards", "1"],
        "--farm local, 3 shards": [facetfit, "-q", "report", *SETTINGS, "--farm", "local", "--shards", "3"],
    }
    times = {name: statistics.median(seconds(c) for _ in range(repeats)) for name, c in runs.items()}
    base = times["one process"]
    print("| built-in report (7 materials, " + " ".join(SETTINGS) + ") | wall time | ratio |")
    print("|---|---|---|")
    for name, t in times.items():
        print(f"| {name} | {t:.2f} s | {t / base:.2f} |")


if __name__ == "__main__":
    main(sys.argv[1], int(sys.argv[2]) if len(sys.argv) > 2 else 3)
