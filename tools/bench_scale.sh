#!/usr/bin/env bash
# Scale benchmark, before and after in one run (tools/bench_scale.py; docs/benchmarks.md#scale).
# Builds this checkout (build/) and the commit BEFORE (default a3f8169, the last commit before
# the work on scale) in a git worktree of its own (bench/scale/before-src, before-build), makes
# tools/make_levels.py's GPU-instanced levels of 1,900, 10,000 and 50,000 copies under a sun and
# level-instances at 2,000 nodes, and bakes each at defaults with both binaries one after the
# other, plus bevy's Cornell box as the yardstick for time: exit, seconds, peak RSS, texels, BVH
# build and seams seconds; writes bench/scale/scale.csv and bench/scale/scale.png (peak memory
# against copies). Each bake is stopped at TIMEOUT seconds (default 900) and marked `timeout`.
# Not part of the tests: the before binary needs over an hour for the three GPU levels.
#   usage: tools/bench_scale.sh [--before REF|--after-only] [--timeout S] [--copies 1900,10000,50000]
set -euo pipefail
cd "$(dirname "$0")/.."
before_ref=a3f8169
timeout=900
copies=1900,10000,50000
while [ $# -gt 0 ]; do
  case $1 in
    --before) before_ref=$2; shift 2 ;;
    --after-only) before_ref=-; shift ;;
    --timeout) timeout=$2; shift 2 ;;
    --copies) copies=$2; shift 2 ;;
    -h|--help) sed -n '2,11p' "$0"; exit 0 ;;
    *) echo "bench_scale: unknown argument $1 (see --help)"; exit 2 ;;
  esac
done
[[ $timeout =~ ^[1-9][0-9]*$ ]] || { echo "bench_scale: --timeout needs seconds"; exit 2; }
[[ $copies =~ ^[1-9][0-9]*(,[1-9][0-9]*)*$ ]] || { echo "bench_scale: --copies needs a list such as 1900,10000"; exit 2; }
tools/setup.sh build
work=bench/scale
mkdir -p "$work" bench/levels
levels=()
for n in ${copies//,/ }; do
  [ -f bench/levels/level-gpu-$n.glb ] || /usr/bin/python3 tools/make_levels.py bench/levels gpu:$n > /dev/null
  levels+=("bench/levels/level-gpu-$n.glb=$n")
done
[ -f bench/levels/level-instances-2000.glb ] || /usr/bin/python3 tools/make_levels.py bench/levels instances:2000 > /dev/null
levels+=("bench/levels/level-instances-2000.glb" "assets/scenes/cornell-box-bevy/CornellBox.glb")

before=-
if [ "$before_ref" != "-" ]; then
  before=$(tools/build_ref.sh "$before_ref" "$work")
fi
/usr/bin/python3 tools/bench_scale.py "$before" build/lmbake "$work" "$work/scale.csv" "$work/scale.png" "$timeout" \
  "${levels[@]}"
