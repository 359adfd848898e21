#!/usr/bin/env bash
# Builds lmbake at git commit REF in a worktree of its own, once per commit, for the benchmarks
# that compare a before and an after binary side by side (bench_threads.sh, bench_scale.sh).
#   usage: tools/build_ref.sh REF WORKDIR   (prints WORKDIR/before-build/lmbake)
# The worktree is WORKDIR/before-src, the build WORKDIR/before-build (its file `commit` says
# which commit it holds); the log WORKDIR/before-build.log.
set -euo pipefail
cd "$(dirname "$0")/.."
ref=$1 work=$2
commit=$(git rev-parse --verify "$ref^{commit}")
src=$work/before-src bld=$work/before-build
mkdir -p "$work"
if [ ! -x "$bld/lmbake" ] || [ "$(cat "$bld/commit" 2>/dev/null)" != "$commit" ]; then
  echo "build_ref: building $ref ($commit) in $bld" >&2
  git worktree remove --force "$src" 2>/dev/null || rm -rf "$src"
  git worktree prune
  git worktree add --detach "$src" "$commit" > /dev/null
  cmake -S "$src" -B "$bld" -DCMAKE_BUILD_TYPE=Release > "$work/before-build.log" 2>&1 &&
    cmake --build "$bld" -j2 --target lmbake >> "$work/before-build.log" 2>&1 ||
    { tail -n 20 "$work/before-build.log" >&2; echo "build_ref: building $ref failed" >&2; exit 1; }
  echo "$commit" > "$bld/commit"
fi
echo "$bld/lmbake"
