#!/usr/bin/env bash
# The farm benchmark (docs/benchmarks.md#farm): on this machine, `lmbake farm parallel` with 2
# workers x 1 thread against `lmbake bake --threads 2`, side by side, ROUNDS rounds (default 3)
# on bevy's Cornell box and level-single-10 (58k triangles, 1.18M texels) at defaults; then the
# critical path on N machines (1, 4 and 16 shards) against `lmbake bake --threads 1` on
# level-single-10. Every output is compared with the bake's, byte for byte. Writes
# bench/farm.csv and bench/farm.png. Not part of the tests (about 25 minutes).
#   usage: tools/bench_farm.sh [ROUNDS] [SHARDS_LIST] [BEFORE_LMBAKE]
# BEFORE_LMBAKE: another lmbake (the commit before a change) measured side by side with this one.
set -euo pipefail
cd "$(dirname "$0")/.."
LMB_SETUP_PACKAGES=parallel tools/setup.sh build
mkdir -p bench/levels
[ -f bench/levels/level-single-10.glb ] || /usr/bin/python3 tools/make_levels.py bench/levels single:10
LMB_BENCH_BEFORE="${3:-}" /usr/bin/python3 tools/bench_farm.py build/lmbake bench/farm-work bench/farm.csv bench/farm.png "${1:-3}" \
  "${2:-1,4,16}" assets/scenes/cornell-box-bevy/CornellBox.glb bench/levels/level-single-10.glb
