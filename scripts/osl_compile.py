"""Compiles every shader of osl/ with Cycles' own OSL compiler (bpy wheel). Exit 1 with the compiler's
messages when one fails. Usage: python osl_compile.py OSL_FOLDER OUTPUT_FOLDER"""
import glob
import os
import sys

import bpy  # noqa: F401  (loads Cycles)
import _cycles


def main():
    src, out = sys.argv[1], sys.argv[2]
    os.makedirs(out, exist_ok=True)
    failed = []
    for shader in sorted(glob.glob(os.path.join(src, "*.osl"))):
        oso = os.path.join(out, os.path.splitext(os.path.basename(shader))[0] + ".oso")
        ok = _cycles.osl_compile(shader, oso)
        print(("compiled " if ok else "FAILED   ") + shader)
        if not ok:
            failed.append(shader)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
