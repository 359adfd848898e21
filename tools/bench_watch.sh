#!/usr/bin/env bash
# The artist's loop benchmark (docs/watch.md#cost): `lmbake preview --watch` of level-single-10
# and bevy's Cornell box; a light made brighter in the file, then moved; the seconds from each
# save to the quick picture and to the final one, against a plain `lmbake bake` of the same file
# run right after, and the quick picture's 9 x 9-averaged error against the final. Writes
# bench/watch.csv. About 10 minutes on 2 cores. Not part of the tests.
#   usage: tools/bench_watch.sh
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh build
mkdir -p bench
[ -f bench/levels/level-single-10.glb ] || /usr/bin/python3 tools/make_levels.py bench/levels single:10 > /dev/null
/usr/bin/python3 tools/bench_watch.py build/lmbake bench/watch.csv bench/levels/level-single-10.glb \
  assets/scenes/cornell-box-bevy/CornellBox.glb
column -s, -t bench/watch.csv
