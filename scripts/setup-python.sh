#!/usr/bin/env bash
# The Python module (docs/python.md) built and installed by `pip install .` into a venv of the build, for
# its tests (label python) and the example of docs/python.md. The build folder persists
# (pyproject.toml), so a second run rebuilds only what changed.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
venv=${1:-build/py-venv}
python=$("$here/setup-venv.sh" "$venv" "scikit_build_core, pybind11, numpy, pytest, matplotlib, MaterialX, hypothesis, PyOpenColorIO, h5py, pxr.UsdValidation" \
  "scikit-build-core>=0.10" "pybind11>=2.12" "numpy" "pytest" "matplotlib" "materialx" "hypothesis" "opencolorio" "h5py" "usd-core")
# No build isolation: the build tools are the venv's, so nothing is fetched again on each run.
"$python" -m pip install --quiet --no-build-isolation "$here/.."
echo "$python"
