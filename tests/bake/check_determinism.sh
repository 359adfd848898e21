#!/usr/bin/env bash
# Same input and seed at 1, 2, 3 and 7 threads: every output file byte-identical (EXR, HDR,
# PNG, KTX2, RGBM, mask, shadowmask, directional maps, glTF, buffers, records), on two bakes
# that between them run every stage:
#   bevy's Cornell box under a sky: emissive ceiling and sky, the direct light's refinement,
#     both denoiser passes, fireflies, directional maps;
#   bevy's mixed-lighting scene under a sky: curved meshes (seams stitched), its sun an
#     `indirect` light (deferred light and the shadowmask), textures.
#   a foliage level (tools/bench_foliage.py, 4 trees) with a glass pane and a blended veil under a
#     sun and a sky: alpha cut-outs, coverage and transmission on every kind of ray (Embree's
#     filters meet the surfaces in an order that may change with the BVH; the light must not).
# The logs must show each stage, so that the test cannot pass with one silently off. 3 and 7
# threads cut every loop unevenly on any machine.
# usage: check_determinism.sh LMBAKE SCENES_DIR WORKDIR [THREADS]
#   THREADS: the thread counts, 1 first (default "1 2 3 7"; the sanitizer build, whose job is
#   memory errors, runs "1 3")
set -euo pipefail
lmbake=$1 scenes=$2 work=$3
read -r -a counts <<<"${4:-1 2 3 7}"
others=("${counts[@]:1}")
rm -rf "$work"
mkdir -p "$work"
cat > "$work/box.yaml" <<'EOF'
atlas: {texels: 15000}
sky: {intensity: 2}
output: {formats: [exr, hdr, png, ktx2, rgbm, mask], directional: true}
EOF
cat > "$work/foliage.yaml" <<'EOF'
atlas: {texels: 8000}
samples: {gather: 32, bounce: 16}
sky: {intensity: 2000}
output: {formats: [exr, mask]}
EOF
cat > "$work/mixed.yaml" <<'EOF'
atlas: {texels: 6000}
samples: {gather: 32, bounce: 16}
sky: {intensity: 2}
output: {formats: [exr, hdr, png, ktx2, rgbm, mask], directional: true, shadowmask: true}
lights: {modes: [{match: "*", mode: indirect}]}
EOF

# bake NAME SCENE [FILES]: NAME at each thread count, then every file compared with 1 thread's
# (at least FILES of them, default 12)
bake() {
  local name=$1 scene=$2 least=${3:-12} n=0
  for t in "${counts[@]}"; do
    "$lmbake" bake "$scene" -c "$work/$name.yaml" -o "$work/$name-t$t" --threads "$t" > "$work/$name-t$t.log" 2>&1
  done
  for f in "$work/$name-t1"/*; do
    for t in "${others[@]}"; do
      cmp "$f" "$work/$name-t$t/$(basename "$f")"
    done
    n=$((n + 1))
  done
  for t in "${others[@]}"; do
    [ "$(ls "$work/$name-t$t" | wc -l)" -eq "$n" ] || { echo "determinism: $name at $t threads wrote other files"; exit 1; }
  done
  echo "determinism: $name: $n files byte-identical at ${counts[*]} threads"
  [ "$n" -ge "$least" ]
}

# ran LOG PATTERN...: each pattern is in the log
ran() {
  local log=$1
  shift
  for stage in "$@"; do
    grep -q -e "$stage" "$log" || { echo "determinism: the bake did not run '$stage' (see $log)"; exit 1; }
  done
}

bake box "$scenes/cornell-box-bevy/CornellBox.glb"
ran "$work/box-t1.log" 'sky: uniform' ' 2 emissive triangles' 'took more samples' 'denoise: the final gather' \
  'denoise: the light with its direct part' 'directions: done'
if grep -q ' 0 of [0-9]* texels (0.0%) took more samples' "$work/box-t1.log"; then
  echo "determinism: no texel was refined"
  exit 1
fi
/usr/bin/python3 -c "import sys; sys.path.insert(0, '$(dirname "$0")/../../tools'); import bench_foliage as b; \
b.level(4, panes=True).write('$work/foliage.gltf')"
bake foliage "$work/foliage.gltf" 3
ran "$work/foliage-t1.log" 'materials: [1-9][0-9]* placed triangles have alpha cut-outs (alphaMode MASK), [1-9][0-9]* let light through in part'
bake mixed "$scenes/mixed-lighting-bevy/MixedLightingExample.gltf"
ran "$work/mixed-t1.log" 'sky: uniform' "light 'Sun': indirect, shadowmask channel R" 'seams: [1-9][0-9]* edges stitched'
