#!/usr/bin/env bash
# Leak benchmark (tools/bench_leaks.py): the leak suite's scenes (tools/leak_scenes.py) baked with
# no config at three texel densities, and what their dark regions read on lightmaps, probes and
# probe-lit points. With a second binary (e.g. one built from an older commit) both run side by
# side. Writes bench/leaks.csv and bench/leaks.md. About 30 minutes for two binaries on 2 cores
# (--quick: about 8). Not part of the tests.
#   usage: tools/bench_leaks.sh [LMBAKE_BEFORE] [--quick]
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh build
mkdir -p bench
/usr/bin/python3 tools/bench_leaks.py bench/leaks build/lmbake "$@"
cp bench/leaks/leaks.csv bench/leaks/leaks.md bench/
