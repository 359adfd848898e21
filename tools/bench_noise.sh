#!/usr/bin/env bash
# Noise against time (tools/bench_noise.py): bevy's Cornell box, the two-spots room and bevy's
# MixedLightingExample, each baked with fixed sample counts (1x, 2x) and with adaptive sampling
# (samples.noise 1% on 1x and 2x the counts), seeds 1 and 2; per-texel and 9 x 9 noise from the
# two seeds, and bake time. Writes bench/noise.csv, bench/noise.md and bench/noise.png. About
# 20 minutes on 2 cores. Not part of the tests.
#   usage: tools/bench_noise.sh [cornell|two-spots|mixed ...]   (default: all three)
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh build
mkdir -p bench
/usr/bin/python3 tools/bench_noise.py build/lmbake bench "$@"
