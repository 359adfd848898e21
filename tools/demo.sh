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
if [ -n "$(ls -A "$out/cornell-box-bevy" 2>/dev/null)" ]; then
  echo "demo: output in $out/cornell-box-bevy"
else
  echo "demo: nothing written yet: the stages after load are still to come (see the bake line above)"
fi
