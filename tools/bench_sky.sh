#!/usr/bin/env bash
# Outdoor benchmark (tools/bench_sky.py): a generated open level with no materials baked with no
# config, with a sky, and with a sky and a default albedo; time, rays/s, black texels, and preview
# shots from inside the level. Writes bench/sky.csv, bench/sky.md, bench/sky-lit.png and
# bench/sky-lightmap.png. A few minutes on 2 cores. Not part of the tests.
#   usage: tools/bench_sky.sh [ROOMS]   (default 10: level-single-10, 58k triangles)
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh build
mkdir -p bench
/usr/bin/python3 tools/bench_sky.py build/lmbake bench "${1:-10}"
