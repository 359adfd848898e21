#!/usr/bin/env bash
# Peak memory per texel (tools/bench_memory.py): bevy's Cornell box baked at 2k texels (the
# base) and at 2M texels, `bounces: 1`, the other keys at their defaults, each under
# /usr/bin/time -v. Writes bench/memory.csv and prints bytes per texel above the base.
# About 3 minutes on 2 cores. Not part of the tests.
#   usage: tools/bench_memory.sh [TEXELS]   (default 2000000)
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh build
mkdir -p bench
/usr/bin/python3 tools/bench_memory.py build/lmbake bench "${1:-2000000}"
