#!/usr/bin/env python3
"""full_disk.py FACETFIT: facetfit's outputs on a filesystem that fills up (ctest label faults).

Mounts small tmpfs filesystems (skips, exit 77, where mounting is not allowed), and at each size runs
`render -o X.exr --png X.png` and `bake` into them. Whatever the exit status, every file left under a
final name must read back whole, no temporary may survive, and exit status 0 must mean every output is
there. Prints the counts: truncated outputs and false successes must both be 0.
"""
import json
import os
import subprocess
import sys
import tempfile

SKIP = 77


def readable(path):
    if path.endswith(".json"):
        try:
            json.load(open(path))
            return True
        except ValueError:
            return False
    return subprocess.run(["oiiotool", path, "--printstats"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode == 0


def check(root, expected, status, counts):
    for dirpath, _, files in os.walk(root):
        for name in files:
            path = os.path.join(dirpath, name)
            if ".tmp-" in name:
                counts["temporaries"] += 1
                print("temporary left:", path)
            elif not readable(path):
                counts["truncated"] += 1
                print("truncated output under its final name:", path)
    if status == 0 and not all(os.path.exists(os.path.join(root, e)) for e in expected):
        counts["false_successes"] += 1
        print("exit 0 without every output:", root)


def main(facetfit):
    counts = {"runs": 0, "failures_reported": 0, "truncated": 0, "false_successes": 0, "temporaries": 0}
    with tempfile.TemporaryDirectory() as tmp:
        mnt = os.path.join(tmp, "disk")
        os.mkdir(mnt)
        for kib in range(100, 1000, 60):
            if subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={kib}k", "tmpfs", mnt], stderr=subprocess.DEVNULL).returncode != 0:
                print("full_disk: skipped: cannot mount a tmpfs here (needs root or CAP_SYS_ADMIN)")
                return SKIP
            try:
                runs = [
                    (["render", "-o", f"{mnt}/a.exr", "--png", f"{mnt}/a.png", "--width", "256", "--height", "256", "--spp", "1"],
                     ["a.exr", "a.png"]),
                    (["bake", "builtin:gold-ggx-0.15", "builtin:red-plastic", "-o", f"{mnt}/luts", "--refine", "none"],
                     ["luts/gold-ggx-0.15.exr", "luts/red-plastic.exr", "luts/index.json"]),
                ]
                for args, expected in runs:
                    status = subprocess.run([facetfit] + args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode
                    counts["runs"] += 1
                    counts["failures_reported"] += status != 0
                    check(mnt, expected, status, counts)
                    subprocess.run(["sh", "-c", f"rm -rf {mnt}/*"], check=True)
            finally:
                subprocess.run(["umount", mnt], check=True)
    print("full_disk:", json.dumps(counts))
    return 1 if counts["truncated"] or counts["false_successes"] or counts["temporaries"] else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
