#!/usr/bin/env bash
# The farm benchmark (issue 13): lmbake bake against 'lmbake farm parallel' in 1, 2 and 4 shards
# on level-single-10 (58k triangles, 1.18M texels at defaults; the gathers are most of the bake),
# side by side, ROUNDS rounds (default 2). Writes bench/farm.csv and bench/farm.png. Not part of
# the tests (about 10 minutes).   usage: tools/bench_farm.sh [ROUNDS] [CONFIG]
# With CONFIG (e.g. tools/bench_farm_long.yaml: 4x the gather rays) the results go to
# bench/farm-<config name>.csv and .png.
set -euo pipefail
config=${2:+$(realpath "$2")}
cd "$(dirname "$0")/.."
LMB_SETUP_PACKAGES=parallel tools/setup.sh build
mkdir -p bench/levels
[ -f bench/levels/level-single-10.glb ] || /usr/bin/python3 tools/make_levels.py bench/levels single:10
name=farm
if [ -n "$config" ]; then
  name=farm-$(basename "$config" .yaml)
fi
/usr/bin/python3 tools/bench_farm.py build/lmbake bench/levels/level-single-10.glb "bench/$name-work" \
  "bench/$name.csv" "bench/$name.png" "${1:-2}" ${config:+"$config"}
