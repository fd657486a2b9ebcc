#!/usr/bin/env bash
# Blender's bpy wheel (Cycles with OSL, headless on CPU) in a venv of the build, for the Cycles
# comparison (make bench) and the OSL tests. Python 3.11; numpy < 2 as bpy 5.0 needs.
exec "$(dirname "$0")/setup-venv.sh" "${1:-build/bpy-venv}" bpy "bpy==5.0.1" "numpy<2"
