#!/usr/bin/env bash
# Blender's bpy wheel (Cycles with OSL, headless on CPU) in a venv of the build, for the Cycles
# comparison (make bench) and the OSL tests. Python 3.11; numpy < 2 as bpy 5.0 needs.
set -euo pipefail
venv="${1:-build/bpy-venv}"
python=$(command -v python3.11 || command -v python3)
if [[ ! -x "$venv/bin/python" ]]; then
  "$python" -m venv "$venv"
fi
if ! "$venv/bin/python" -c "import bpy" >/dev/null 2>&1; then
  "$venv/bin/pip" install --quiet "bpy==5.0.1" "numpy<2"
fi
echo "$venv/bin/python"
