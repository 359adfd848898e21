#!/usr/bin/env bash
# Noise and error against time (tools/bench_noise.py): bevy's Cornell box, the two-spots room
# and bevy's MixedLightingExample, each baked with fixed sample counts (1x, 2x) and with adaptive
# sampling (samples.noise 1% on 1x and 2x the counts) without the denoiser, and at the defaults
# (adaptive sampling and the denoiser), seeds 1 and 2; per-texel and 9 x 9 noise from the two
# seeds, error against a converged reference (baked once per scene, kept in bench/noise-work),
# and bake time. Writes bench/noise.csv, bench/noise.md and bench/noise.png. About 50 minutes on
# 2 cores the first time (the references), 30 after. Not part of the tests.
#   usage: tools/bench_noise.sh [cornell|two-spots|mixed ...]   (default: all three)
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh build
mkdir -p bench
/usr/bin/python3 tools/bench_noise.py build/lmbake bench "$@"
