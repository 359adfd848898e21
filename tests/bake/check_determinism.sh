#!/usr/bin/env bash
# Same input and seed, 1 thread and 2 threads: byte-identical EXR lightmaps and glTF.
# usage: check_determinism.sh LMBAKE SCENE WORKDIR
set -euo pipefail
lmbake=$1 scene=$2 work=$3
rm -rf "$work/t1" "$work/t2"
mkdir -p "$work"
printf 'samples: {texel: 4, direct: 16}\ntexel_density: 0.25\n' > "$work/det.yaml"
"$lmbake" bake "$scene" -c "$work/det.yaml" -o "$work/t1" --threads 1 -q
"$lmbake" bake "$scene" -c "$work/det.yaml" -o "$work/t2" --threads 2 -q
n=0
for f in "$work/t1"/*.exr "$work/t1"/*.gltf "$work/t1"/*.bin; do
  cmp "$f" "$work/t2/$(basename "$f")"
  n=$((n + 1))
done
echo "determinism: $n files byte-identical at 1 and 2 threads"
[ "$n" -ge 3 ]
