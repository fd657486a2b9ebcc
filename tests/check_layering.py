#!/usr/bin/env python3
"""check_layering.py LIB_DIR: fails if any file of lib/ includes a folder above its own.

The order (docs/conventions.md): core -> model -> io -> fit -> lut -> color, render -> report; a file may
include its own folder and those below it.
"""
import glob
import os
import re
import sys

RANK = {"core": 0, "model": 1, "io": 2, "fit": 3, "lut": 4, "color": 5, "render": 5, "report": 6}


def main(lib):
    bad = []
    for path in sorted(glob.glob(os.path.join(lib, "*", "*.h")) + glob.glob(os.path.join(lib, "*", "*.cpp"))):
        folder = os.path.basename(os.path.dirname(path))
        for target in re.findall(r'#include "([a-z_]+)/[^"]+"', open(path).read()):
            if target not in RANK or folder not in RANK:
                bad.append(f"{path}: unknown folder in the layering ({folder} -> {target})")
            elif RANK[target] > RANK[folder] or (RANK[target] == RANK[folder] and target != folder):
                bad.append(f"{path}: {folder}/ includes {target}/, which is not below it")
    for line in bad:
        print(line)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
