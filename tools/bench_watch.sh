#!/usr/bin/env bash
# The artist's loop benchmark (docs/watch.md#cost): `lmbake preview --watch` of level-single-10
# and bevy's Cornell box; a light made brighter in the file, then moved; the seconds from each
# save to the quick picture and to the final one, against a plain `lmbake bake` of the same file
# run right after, and the quick picture's 9 x 9-averaged error against the final. Writes
# bench/watch.csv (or bench/watch-NAME.csv for levels given). About 10 minutes on 2 cores with
# the default levels. Not part of the tests.
#   usage: tools/bench_watch.sh [LEVEL[:LIGHT] ...]   (LIGHT: the point light to edit, by name)
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh build
mkdir -p bench
[ -f bench/levels/level-single-10.glb ] || /usr/bin/python3 tools/make_levels.py bench/levels single:10 > /dev/null
if [ $# -gt 0 ]; then
  csv=bench/watch-$(basename "${1%.*}").csv
  /usr/bin/python3 tools/bench_watch.py build/lmbake "$csv" "$@"
else
  csv=bench/watch.csv
  /usr/bin/python3 tools/bench_watch.py build/lmbake "$csv" "bench/levels/level-single-10.glb:Lamp 1" \
    assets/scenes/cornell-box-bevy/CornellBox.glb
fi
column -s, -t "$csv"
