#!/usr/bin/env python3
"""kills.py FACETFIT: `render` and `report` killed (SIGKILL) at spread-out moments (ctest label faults).

After each kill every file under a final name must read back whole; the next complete run must leave no
temporary and exit 0; and a report killed while re-rendering at another size must not have its images
reused by the next run (the images and report.json must agree on the size). Prints the counts, which
must be 0: truncated outputs, temporaries left, images of the wrong size.
"""
import json
import os
import signal
import struct
import subprocess
import sys
import tempfile
import time


def readable(path):
    if path.endswith(".json") or path.endswith(".svg") or path.endswith(".html") or os.path.basename(path) == "complete":
        return os.path.getsize(path) > 0 and (not path.endswith(".json") or _json_ok(path))
    return subprocess.run(["oiiotool", path, "--printstats"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode == 0


def _json_ok(path):
    try:
        json.load(open(path))
        return True
    except ValueError:
        return False


def png_width(path):
    with open(path, "rb") as f:
        head = f.read(24)
    return struct.unpack(">I", head[16:20])[0]


def survey(root, counts, temporaries_allowed):
    for dirpath, _, files in os.walk(root):
        for name in files:
            path = os.path.join(dirpath, name)
            if ".tmp-" in name:
                if not temporaries_allowed:
                    counts["temporaries"] += 1
                    print("temporary left after a complete run:", path)
            elif not readable(path):
                counts["truncated"] += 1
                print("truncated output under its final name:", path)


def killed(command, delay):
    p = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    time.sleep(delay)
    p.send_signal(signal.SIGKILL)
    p.wait()


def main(facetfit):
    counts = {"truncated": 0, "temporaries": 0, "wrong_size": 0}
    kills = 0
    with tempfile.TemporaryDirectory() as tmp:
        exr, png = os.path.join(tmp, "r.exr"), os.path.join(tmp, "r.png")
        render = [facetfit, "render", "-o", exr, "--png", png, "--width", "96", "--height", "96", "--spp", "8"]
        for delay in (0.05, 0.2, 0.5, 0.9):
            killed(render, delay)
            kills += 1
            survey(tmp, counts, temporaries_allowed=True)
        assert subprocess.run(render, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode == 0
        survey(tmp, counts, temporaries_allowed=False)

        report = os.path.join(tmp, "report")
        base = [facetfit, "report", "builtin:gold-ggx-0.15", "builtin:red-plastic", "--refine", "none", "--spp", "2", "-o", report]
        assert subprocess.run(base + ["--size", "16"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode == 0
        for delay in (0.3, 0.7, 1.2, 1.8):
            killed(base + ["--size", "24", "--force"], delay)
            kills += 1
            survey(report, counts, temporaries_allowed=True)
            # The next run at the first size must show images of that size, none of the killed run's.
            assert subprocess.run(base + ["--size", "16"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode == 0
            survey(report, counts, temporaries_allowed=False)
            size = json.load(open(os.path.join(report, "report.json")))["settings"]["size"]
            for dirpath, _, files in os.walk(os.path.join(report, "images")):
                for name in files:
                    if name.endswith(".png") and ".tmp-" not in name and png_width(os.path.join(dirpath, name)) != size:
                        counts["wrong_size"] += 1
                        print("image of another size than report.json says:", os.path.join(dirpath, name))
    print(f"{kills} kills: {counts['truncated']} truncated outputs, {counts['temporaries']} temporaries left, "
          f"{counts['wrong_size']} images of the wrong size")
    return 0 if not any(counts.values()) else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
