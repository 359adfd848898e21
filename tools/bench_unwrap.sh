#!/usr/bin/env bash
# Unwrap benchmark: builds, runs tools/bench_unwrap.c, writes bench/unwrap.csv and
# bench/unwrap.png (coverage and charting time against xatlas). Not part of the tests.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh build
mkdir -p bench
build/bench_unwrap "${1:-1024}" | tee bench/unwrap.csv
/usr/bin/python3 tools/plot_unwrap.py bench/unwrap.csv bench/unwrap.png
echo "bench: wrote bench/unwrap.csv and bench/unwrap.png"
