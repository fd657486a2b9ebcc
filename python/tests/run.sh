#!/usr/bin/env bash
# Runs PYTHON ARGS... if PYTHON is a venv with the facetfit module installed; otherwise says how to get
# one and exits 77 (ctest: skipped).
python=$1
shift
if [[ ! -x "$python" ]] || ! "$python" -c "import facetfit" >/dev/null 2>&1; then
  echo "skipped: no venv with the facetfit module at $python (run: make python)"
  exit 77
fi
exec "$python" "$@"
