#!/usr/bin/env bash
# README command 1: install what is missing, build, bake the bundled demo scene, and print
# where the output is.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh build
out=${LMB_DEMO_OUT:-$PWD/demo-out}
scene=assets/scenes/cornell-box-bevy/CornellBox.glb
echo "demo: baking $scene"
build/lmbake bake "$scene" -c assets/demo-config.yaml -o "$out/cornell-box-bevy"
echo "demo: output in $out"
