#!/usr/bin/env bash
# Relighting a level with light groups, side by side (tools/bench_relight.py, docs/light-groups.md):
# each edit read back with --layout-cache against a bake of the edited level without it, byte for
# byte. Writes bench/relight.csv and bench/relight.png. Not part of the tests (about 15 minutes).
#   usage: tools/bench_relight.sh [LEVEL ...]   (e.g. sun-lamps: only that level)
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh build
mkdir -p bench/levels
[ -f bench/levels/level-single-10.glb ] || /usr/bin/python3 tools/make_levels.py bench/levels single:10
/usr/bin/python3 tools/bench_relight.py build/lmbake bench "$@"
