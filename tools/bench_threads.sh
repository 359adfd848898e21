#!/usr/bin/env bash
# Thread scaling per stage, before and after, side by side in one run (tools/bench_threads.py;
# docs/benchmarks.md#threads). Builds this checkout (build/) and the commit BEFORE (default
# e468856, the last commit before the work on threads) in a git worktree of its own
# (bench/threads/before-src, bench/threads/before-build), then bakes level-single-10
# (tools/make_levels.py) and bevy's Cornell box at defaults with each binary at each thread
# count, alternating, then as many 1-thread bakes at once as the largest count (threads against
# processes). Prints per stage the seconds and speed-ups, the serial fraction, and
# writes bench/threads/threads.csv and bench/threads/threads.png. Not part of the tests
# (about 11 minutes on 2 cores, plus about 4 to build BEFORE the first time).
#   usage: tools/bench_threads.sh [--before REF] [--threads 1,2] [--rounds N] [SCENE[=CONFIG] ...]
#   --rounds N: the whole sequence N times (default 1); figures are the rounds' medians
set -euo pipefail
cd "$(dirname "$0")/.."
before_ref=e468856
threads=1,2
rounds=1
scenes=()
while [ $# -gt 0 ]; do
  case $1 in
    --before) before_ref=$2; shift 2 ;;
    --threads) threads=$2; shift 2 ;;
    --rounds) rounds=$2; shift 2 ;;
    -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
    *) scenes+=("$1"); shift ;;
  esac
done
[[ $threads =~ ^[1-9][0-9]*(,[1-9][0-9]*)+$ ]] || { echo "bench_threads: --threads needs a list such as 1,2"; exit 2; }
[[ $rounds =~ ^[1-9][0-9]?$ ]] || { echo "bench_threads: --rounds needs a number 1..99"; exit 2; }
tools/setup.sh build
work=bench/threads
mkdir -p "$work" bench/levels
[ -f bench/levels/level-single-10.glb ] || /usr/bin/python3 tools/make_levels.py bench/levels single:10
if [ ${#scenes[@]} -eq 0 ]; then
  scenes=(bench/levels/level-single-10.glb assets/scenes/cornell-box-bevy/CornellBox.glb)
fi

# the binary of BEFORE, built once per commit
before=$(tools/build_ref.sh "$before_ref" "$work")
/usr/bin/python3 tools/bench_threads.py "$before" build/lmbake "$work/runs" "$work/threads.csv" \
  "$work/threads.png" "$threads" "$rounds" "${scenes[@]}"
