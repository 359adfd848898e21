#!/usr/bin/env bash
# Final-gather benchmark (tools/bench_gather.py): classic vs the default (guided AMIS) vs
# unguided defensive AMIS vs the paper's AMIS, error against time on five generated scenes, and
# what gather.direct_at_hits costs and buys; writes bench/gather.csv, gather-direct-at-hits.csv,
# bench/gather.md (summary, equal-samples and equal-time tables), bench/gather.png and
# side-by-side images bench/gather-<scene>.png. About 12 minutes on 2 cores. Not part of the tests.
#   BENCH_REF_PATHS (8192), BENCH_CONVERGED_RAYS (16384), BENCH_THREADS (2), BENCH_REPEAT (3) tune it.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh build
mkdir -p bench
/usr/bin/python3 tools/bench_gather.py build/lmbake bench
