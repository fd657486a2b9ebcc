#!/usr/bin/env bash
# A Python venv of the build holding one PyPI package set: creates VENV if absent and installs SPEC...
# unless MODULE already imports. Prints the venv's python.
# Usage: scripts/setup-venv.sh VENV MODULE SPEC...
set -euo pipefail
venv=$1 module=$2
shift 2
python=$(command -v python3.11 || command -v python3)
if [[ ! -x "$venv/bin/python" ]]; then
  "$python" -m venv "$venv"
fi
if ! "$venv/bin/python" -c "import $module" >/dev/null 2>&1; then
  "$venv/bin/pip" install --quiet "$@"
fi
echo "$venv/bin/python"
