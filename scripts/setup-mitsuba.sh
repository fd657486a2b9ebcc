#!/usr/bin/env bash
# Mitsuba 3 (PyPI wheel) in a venv of the build: the reference evaluation of RGL files for the parity
# test (label mitsuba). The scalar_rgb variant needs no LLVM.
set -euo pipefail
venv="${1:-build/mitsuba-venv}"
python=$(command -v python3.11 || command -v python3)
if [[ ! -x "$venv/bin/python" ]]; then
  "$python" -m venv "$venv"
fi
if ! "$venv/bin/python" -c "import mitsuba" >/dev/null 2>&1; then
  "$venv/bin/pip" install --quiet "mitsuba==3.9.1" "numpy"
fi
echo "$venv/bin/python"
