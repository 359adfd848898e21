#!/usr/bin/env bash
# Level-scale unwrap + pack benchmark (issue 10): builds, generates the levels, writes
# bench/levels.csv and bench/levels.png (time against triangles and charts, peak memory).
# Also runs the per-mesh unwrap benchmark (bench/unwrap.csv) for coverage. Not part of the tests.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh build
mkdir -p bench
/usr/bin/python3 tools/bench_levels.py build/lmbake bench/levels bench/levels.csv bench/levels.png
build/bench_unwrap 1024 > bench/unwrap.csv
/usr/bin/python3 tools/plot_unwrap.py bench/unwrap.csv bench/unwrap.png
echo "bench: wrote bench/levels.csv, bench/levels.png, bench/unwrap.csv, bench/unwrap.png"
