#!/usr/bin/env python3
"""test_farm.py FACETFIT: `report --farm slurm` on a real one-node Slurm cluster (ctest label farm).

Starts the cluster (tests/farm/slurm_cluster.sh; exit 77, skipped, where Slurm cannot run here) and stops
it afterwards, whatever happens. Checks, against a report made on this machine alone:
  1. the built-in database in 3 shards (--wait) gives the same materials and Delta E values to the digit;
  2. a shard cancelled (scancel) mid-run is submitted again and the published report is whole and equal;
  3. a database path that does not exist fails with one message, submits nothing and publishes nothing.
"""
import json
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
SETTINGS = ["--refine", "none", "--size", "32", "--spp", "4"]


def delta_e(report_dir):
    report = json.load(open(os.path.join(report_dir, "report.json")))
    return {m["name"]: m["delta_e"] for m in report["materials"]}, report["failures"]


def main(facetfit):
    failures = []

    def check(ok, what):
        print(("ok:   " if ok else "FAIL: ") + what)
        if not ok:
            failures.append(what)

    with tempfile.TemporaryDirectory(prefix="facetfit-farm-") as tmp:
        cluster = os.path.join(tmp, "cluster")
        start = subprocess.run([os.path.join(HERE, "slurm_cluster.sh"), "start", cluster], capture_output=True, text=True)
        if start.returncode != 0:
            print(start.stderr.strip() or start.stdout.strip())
            return 77 if start.returncode == 77 else 1
        env = dict(os.environ, SLURM_CONF=start.stdout.strip())
        try:
            single = os.path.join(tmp, "single")
            assert subprocess.run([facetfit, "-q", "report", *SETTINGS, "-o", single], env=env).returncode == 0
            reference, _ = delta_e(single)

            # 1. Three shards on Slurm, waited for.
            farm = os.path.join(tmp, "farm")
            r = subprocess.run([facetfit, "report", *SETTINGS, "--farm", "slurm", "--shards", "3", "--wait", "-o", farm], env=env,
                               capture_output=True, text=True)
            check(r.returncode == 0, f"3 Slurm shards exit 0 ({r.stderr.strip()[-300:]})")
            got, failed = delta_e(farm) if r.returncode == 0 else ({}, ["no report"])
            check(got == reference and not failed, f"merged report equals the single-machine one ({len(got)} materials)")

            # 2. A shard cancelled mid-run is submitted again; the report is whole.
            cancelled = os.path.join(tmp, "cancelled")
            p = subprocess.Popen([facetfit, "report", *SETTINGS, "--force", "--farm", "slurm", "--shards", "3", "--wait", "-o", cancelled],
                                 env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            victim = None
            for _ in range(200):  # the second task, once it runs
                q = subprocess.run(["squeue", "-h", "-o", "%i %T", "-n", "facetfit-report"], env=env, capture_output=True, text=True).stdout
                running = [line.split()[0] for line in q.splitlines() if line.endswith("RUNNING") and line.split()[0].endswith("_2")]
                if running:
                    victim = running[0]
                    break
                time.sleep(0.05)
            if victim:
                time.sleep(0.3)
                subprocess.run(["scancel", victim], env=env)
            out, err = p.communicate(timeout=900)
            check(victim is not None, f"a running shard task was found and cancelled ({victim})")
            check(p.returncode == 0 and "submitting it again" in err, f"the cancelled shard ran again and the farm exit 0 ({err.strip()[-300:]})")
            got, failed = delta_e(cancelled) if p.returncode == 0 else ({}, ["no report"])
            check(got == reference and not failed, "the report after the cancel is whole and equal")

            # 3. A database that does not exist: one line, nothing submitted, nothing published.
            bad = os.path.join(tmp, "bad")
            before = subprocess.run(["squeue", "-h", "-o", "%i"], env=env, capture_output=True, text=True).stdout
            r = subprocess.run([facetfit, "report", os.path.join(tmp, "no-such-db"), "--farm", "slurm", "--shards", "3", "--wait", "-o", bad],
                               env=env, capture_output=True, text=True)
            lines = [line for line in r.stderr.splitlines() if line.strip()]
            check(r.returncode == 1 and len(lines) == 1 and "no-such-db" in lines[0], f"a missing database: exit 1, one line ({r.stderr.strip()})")
            check(not os.path.exists(os.path.join(bad, "report.json")), "a missing database publishes no report")
            after = subprocess.run(["squeue", "-h", "-o", "%i"], env=env, capture_output=True, text=True).stdout
            check(before == after, "a missing database submits nothing")

        finally:
            subprocess.run([os.path.join(HERE, "slurm_cluster.sh"), "stop", cluster])
    print(f"{len(failures)} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
