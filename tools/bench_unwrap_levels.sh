#!/usr/bin/env bash
# Level unwrap benchmark against xatlas: builds, generates the 58k-triangle single-mesh level,
# runs lmbake unwrap and xatlas (npm xatlasjs, tools/xatlas_unwrap.mjs) alternately at the
# default density and at 4x, writes bench/unwrap-levels.csv and bench/unwrap-levels.png.
# Not part of the tests. Usage: tools/bench_unwrap_levels.sh [ROUNDS]
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh build
mkdir -p bench
/usr/bin/python3 tools/bench_unwrap_levels.py build/lmbake bench/levels bench/unwrap-levels.csv \
  bench/unwrap-levels.png "${1:-3}"
