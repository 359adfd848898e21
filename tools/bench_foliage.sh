#!/usr/bin/env bash
# Foliage benchmark (tools/bench_foliage.py): a generated level whose leaves are alpha-cut cards,
# baked as it is and with the leaves opaque, side by side: wall time, rays, rays/s and the ratio.
# Writes bench/foliage.csv and bench/foliage.md. A few minutes on 2 cores. Not part of the tests.
#   usage: tools/bench_foliage.sh [TREES]   (default 40)
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh build
mkdir -p bench
/usr/bin/python3 tools/bench_foliage.py build/lmbake bench "${1:-40}"
