#!/usr/bin/env bash
# README command 1: install what is missing, build, bake the bundled demo scenes and print
# where the output is: the project's own Cornell box with a point light just under the
# ceiling (tools/make_scenes.py) and bevy's Cornell box with its emissive ceiling.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh build
out=${LMB_DEMO_OUT:-$PWD/demo-out}
mkdir -p "$out/scenes"
/usr/bin/python3 tools/make_scenes.py "$out/scenes" >/dev/null
echo "demo: baking the Cornell box with a point light (generated: $out/scenes/cornell-point.gltf)"
build/lmbake bake "$out/scenes/cornell-point.gltf" -c assets/demo-point-config.yaml -o "$out/cornell-point"
echo "demo: baking bevy's Cornell box (assets/scenes/cornell-box-bevy/CornellBox.glb, millimetres) with no config: the defaults"
build/lmbake bake assets/scenes/cornell-box-bevy/CornellBox.glb -o "$out/cornell-box-bevy"
echo "demo: output in $out/cornell-point and $out/cornell-box-bevy (.gltf + lightmap .exr/.hdr/.png)"
