#!/usr/bin/env bash
# File sizes per output format (tools/bench_output_sizes.py): bevy's Cornell box and
# level-single-10 at the defaults, every format and KTX2 variant. Writes
# bench/output-sizes.csv and bench/output-sizes.md. A few minutes on 2 cores. Not part of the tests.
#   usage: tools/bench_output_sizes.sh
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh build
mkdir -p bench
/usr/bin/python3 tools/bench_output_sizes.py build/lmbake bench
