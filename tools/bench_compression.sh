#!/usr/bin/env bash
# KTX2 lightmap formats side by side (tools/bench_compression.py): bevy's Cornell box,
# level-single-10 and a sunlit outdoor level, each baked at the defaults once per KTX2 format;
# bytes per texel on the GPU and on disk, encode seconds against the bake's, error per texel and
# on 9 x 9 averages against the EXR, the seam jump after compression. Writes
# bench/compression.csv, .md and .png. About 10 minutes on 2 cores. Not part of the tests.
#   usage: tools/bench_compression.sh
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh build
mkdir -p bench
/usr/bin/python3 tools/bench_compression.py build/lmbake bench
