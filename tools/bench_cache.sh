#!/usr/bin/env bash
# Irradiance cache benchmark (tools/bench_cache.py): per-texel gathering vs the cache at several
# error settings, RMSE against the path-traced reference vs time on five generated scenes, and
# lmbake's defaults against the path tracer with all bounces. Writes bench/cache.csv,
# bench/cache.md and bench/cache.png. About 10 minutes on 2 cores. Not part of the tests.
#   BENCH_REF_PATHS (4096), BENCH_PT_REF (8192), BENCH_THREADS (2), BENCH_REPEAT (2) tune it.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh build
mkdir -p bench
/usr/bin/python3 tools/bench_cache.py build/lmbake bench
