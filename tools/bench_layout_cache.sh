#!/usr/bin/env bash
# What a kept layout saves (docs/watch.md#what-is-redone): per level, a bake with
# `--layout-cache` fills the cache; then a lighting-only change (lights.intensity_scale: 2 in the
# config) is baked plainly and with the layout read back, one after the other; their seconds, and
# whether their files are the same byte for byte. Writes bench/layout-cache.csv. About 6 minutes
# on 2 cores with the default levels. Not part of the tests.
#   usage: tools/bench_layout_cache.sh [LEVEL ...]   (default: level-single-10, level-gpu-10000)
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh build > /dev/null
levels=("$@")
if [ ${#levels[@]} -eq 0 ]; then
  [ -f bench/levels/level-single-10.glb ] || /usr/bin/python3 tools/make_levels.py bench/levels single:10 > /dev/null
  [ -f bench/levels/level-gpu-10000.glb ] || /usr/bin/python3 tools/make_levels.py bench/levels gpu:10000 > /dev/null
  levels=(bench/levels/level-single-10.glb bench/levels/level-gpu-10000.glb)
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p bench
csv=bench/layout-cache.csv
echo "level,layout_built_s,plain_s,layout_kept_s,saved_s,identical" > "$csv"
printf 'lights: {intensity_scale: 2}\n' > "$work/brighter.yaml"
seconds() { # seconds of a command, its output in $work/log
  local t0 t1
  t0=$(date +%s.%N)
  "$@" > "$work/log" 2>&1
  t1=$(date +%s.%N)
  echo "$t1 - $t0" | bc
}
for level in "${levels[@]}"; do
  name=$(basename "${level%.*}")
  rm -rf "$work/cache" "$work/first" "$work/plain" "$work/kept"
  seconds build/lmbake bake "$level" -o "$work/first" --layout-cache "$work/cache" > /dev/null
  built=$(sed -n 's/^layout: built in \([0-9.]*\) s.*/\1/p' "$work/log")
  plain=$(seconds build/lmbake bake "$level" -c "$work/brighter.yaml" -o "$work/plain")
  kept=$(seconds build/lmbake bake "$level" -c "$work/brighter.yaml" -o "$work/kept" --layout-cache "$work/cache")
  grep -q '^layout: read back' "$work/log" || { echo "$name: the layout was not read back" >&2; exit 1; }
  same=yes
  for f in "$work/plain"/*; do cmp -s "$f" "$work/kept/$(basename "$f")" || same=no; done
  printf '%s,%s,%.1f,%.1f,%.1f,%s\n' "$name" "$built" "$plain" "$kept" "$(echo "$plain - $kept" | bc)" "$same" >> "$csv"
done
column -s, -t "$csv"
