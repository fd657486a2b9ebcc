#!/usr/bin/env bash
# Mitsuba 3 (PyPI wheel) in a venv of the build: the reference evaluation of RGL files for the parity
# test (label mitsuba). The scalar_rgb variant needs no LLVM.
exec "$(dirname "$0")/setup-venv.sh" "${1:-build/mitsuba-venv}" mitsuba "mitsuba==3.9.1" "numpy"
