#!/usr/bin/env bash
# Irradiance cache benchmark (tools/bench_cache.py): per-texel gathering vs the cache at several
# error settings, RMSE against the path-traced reference vs time on five generated scenes, and
# lmbake's defaults against the path tracer with all bounces. Writes bench/cache.csv,
# bench/cache.md and bench/cache.png. Last, the defaults against the stored converged reference
# at 256 texels per unit as well as 64 and 128 (tests/bake/check_defaults.py; the ctest
# defaults_accuracy checks 64 and 128); a miss fails the script. About 11 minutes on 2 cores.
# Not part of the tests.
#   BENCH_REF_PATHS (4096), BENCH_PT_REF (8192), BENCH_THREADS (2), BENCH_REPEAT (2) tune it.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh build
mkdir -p bench
/usr/bin/python3 tools/bench_cache.py build/lmbake bench
(cd tests/bake && /usr/bin/python3 check_defaults.py ../../build/lmbake ../../bench/defaults-accuracy accuracy 64,128,256)
