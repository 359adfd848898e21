#!/usr/bin/env bash
# Fuzzes lmbake's front door with libFuzzer: glTF load, the YAML config, texture
# decoding and the farm's plan decoder (tests/fuzz/fuzz_*.c), built with Debian's clang-14,
# ASan and UBSan.
#   usage: tools/fuzz.sh [SECONDS] [TARGET...]   (default: 60 s; targets gltf config image plan)
#   LMB_FUZZ_BUILD_ONLY=1: build and stop; LMB_FUZZ_PACKAGES_INSTALLED=1: whether its packages are there
# All targets run at once, each for SECONDS of wall time, one process each (the machine's cores
# are shared). Seeds come from assets/ and tests/data (tests/fuzz/CMakeLists.txt has the same
# patterns); what a run adds stays in build-fuzz/corpus/<target> for the next run. First every
# seed and regression input is run once, alone, and the slowest is printed (and written to
# build-fuzz/seed-times.csv). A crash, leak, timeout (> TIMEOUT s per input, below) or
# out-of-memory (> 2 GiB) leaves its input in
# build-fuzz/artifacts/<target>/ and fails the run: copy it to tests/fuzz/regressions/<target>/ (regressions-large/ if it is legal but takes over 1 s here),
# where ctest replays it in every test build, then fix the bug.
# Prints executions, coverage (edges, features) and corpus size per target, and writes
# build-fuzz/fuzz-summary.csv.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
shift || true
targets=("$@")
((${#targets[@]})) || targets=(gltf config image plan)
export LMB_FUZZ_PLAN_SCENE="$PWD/assets/scenes/cornell-box-bevy/CornellBox.glb" # fuzz_plan's scene

# clang-14 with libFuzzer's runtime; libomp for clang's OpenMP
fuzz_packages="clang-14 libclang-rt-14-dev libomp-14-dev"
# LMB_FUZZ_PACKAGES_INSTALLED=1: exit 0 when they are all installed, 1 otherwise (tools/test.sh)
if [ "${LMB_FUZZ_PACKAGES_INSTALLED:-0}" = 1 ]; then
  for p in $fuzz_packages; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || exit 1
  done
  exit 0
fi
LMB_SETUP_PACKAGES="$fuzz_packages" \
LMB_BUILD_TARGETS="${targets[*]/#/fuzz_}" CC=clang-14 CXX=clang++-14 \
  tools/setup.sh build-fuzz -DLMB_FUZZ=ON -DBUILD_TESTING=OFF
# LMB_FUZZ_BUILD_ONLY=1: the build alone (tools/test.sh builds it beside the sanitizer tests)
[ "${LMB_FUZZ_BUILD_ONLY:-0}" = 1 ] && exit 0

out=build-fuzz
# Per-input limit. Measured by the replay below on this machine (2 cores, fuzz build): the
# slowest of the 84 seed and regression inputs takes 0.18 s alone (gltf
# truncated-png-data-uri.gltf); 60 s is over 300x that, so a busy machine (every target fuzzing
# at once, a build or a bake beside them) cannot reach it, while a real hang does.
TIMEOUT=60
seed_files() { # the seeds of one target, as in tests/fuzz/CMakeLists.txt
  case $1 in
    gltf) find assets tests/data -type f \( -name '*.gltf' -o -name '*.glb' \) ;;
    config) find assets tests/preview -type f -name '*.yaml' ;;
    image) find assets -type f \( -name '*.png' -o -name '*.jpg' \) -size -256k ;;
  esac
}
max_len() { case $1 in gltf) echo 65536 ;; config) echo 16384 ;; image) echo 131072 ;; plan) echo 65536 ;; esac; }

for t in "${targets[@]}"; do
  rm -rf "$out/seeds/$t" "$out/artifacts/$t" "$out/logs/$t.log"
  mkdir -p "$out/seeds/$t" "$out/corpus/$t" "$out/artifacts/$t" "$out/logs"
  n=0
  # cut to max_len, as libFuzzer cuts every corpus input it loads: the seeds are what the timed
  # run starts from (ctest replays the whole files: fuzz_regressions_<target>)
  while IFS= read -r f; do head -c "$(max_len "$t")" "$f" >"$out/seeds/$t/$n-$(basename "$f")"; n=$((n + 1)); done < <(seed_files "$t")
  for f in tests/fuzz/regressions/"$t"/*; do [ -f "$f" ] && head -c "$(max_len "$t")" "$f" >"$out/seeds/$t/$(basename "$f")"; done
  if [ "$t" = plan ]; then # the scene's own layout, written by the target
    LMB_FUZZ_PLAN_SEED="$out/seeds/plan/cornell-layout" ASAN_OPTIONS=detect_leaks=0 "$out/tests/fuzz/fuzz_plan" -runs=0 >/dev/null 2>&1
  fi
done

# Every seed and regression input once, alone: how long each takes (libFuzzer prints
# "Executed FILE in N ms" per file given by name).
printf 'target,input,ms\n' >"$out/seed-times.csv"
for t in "${targets[@]}"; do
  find "$out/seeds/$t" -type f -print0 | xargs -0 -r env LSAN_OPTIONS=suppressions="$PWD/tests/fuzz/lsan.supp":print_suppressions=0 \
    ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1:fast_unwind_on_malloc=0 \
    "$out/tests/fuzz/fuzz_$t" -rss_limit_mb=2048 2>&1 |
    sed -n "s|^Executed $out/seeds/$t/\(.*\) in \([0-9]*\) ms\$|$t,\1,\2|p" >>"$out/seed-times.csv" || true
done
slowest=$(tail -n +2 "$out/seed-times.csv" | sort -t, -k3,3n | tail -n1)
echo "fuzz: $(($(wc -l <"$out/seed-times.csv") - 1)) seed and regression inputs run once; slowest: ${slowest:-none} ms (limit ${TIMEOUT} s)"

echo "fuzz: ${targets[*]} for ${seconds} s each (ASan+UBSan; logs in $out/logs)"
pids=()
for t in "${targets[@]}"; do
  dict=()
  [ -f "tests/fuzz/$t.dict" ] && dict=(-dict="tests/fuzz/$t.dict")
  # leaks are checked after every input; a slow input (> TIMEOUT s) is a timeout; 2 GiB is the cap
  LSAN_OPTIONS=suppressions="$PWD/tests/fuzz/lsan.supp":print_suppressions=0 \
  ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1:fast_unwind_on_malloc=0 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    "$out/tests/fuzz/fuzz_$t" "$out/corpus/$t" "$out/seeds/$t" "${dict[@]}" \
      -max_total_time="$seconds" -timeout="$TIMEOUT" -rss_limit_mb=2048 -max_len="$(max_len "$t")" \
      -print_final_stats=1 -artifact_prefix="$out/artifacts/$t/" >"$out/logs/$t.log" 2>&1 &
  pids+=($!)
done
status=0
for i in "${!pids[@]}"; do wait "${pids[$i]}" || status=1; done

# Summary from each log: libFuzzer's final stats and its last coverage line.
printf 'target,seconds,executions,execs_per_s,edges,features,corpus,crashes,leaks,timeouts,ooms\n' >"$out/fuzz-summary.csv"
printf '%-7s %9s %12s %9s %7s %9s %7s %s\n' target seconds executions exec/s edges features corpus "crash/leak/timeout/oom"
for t in "${targets[@]}"; do
  log="$out/logs/$t.log"
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -n1)
  cov=$({ grep -oE 'cov: [0-9]+ ft: [0-9]+ corp: [0-9]+' "$log" || true; } | tail -n1)
  edges=$(awk '{print $2}' <<<"$cov"); features=$(awk '{print $4}' <<<"$cov"); corpus=$(awk '{print $6}' <<<"$cov")
  art="$out/artifacts/$t"
  crashes=$(find "$art" -name 'crash-*' | wc -l); leaks=$(find "$art" -name 'leak-*' | wc -l)
  timeouts=$(find "$art" -name 'timeout-*' | wc -l); ooms=$(find "$art" -name 'oom-*' | wc -l)
  printf '%s,%s,%s,%s,%s,%s,%s,%s,%s,%s,%s\n' "$t" "$seconds" "${runs:-0}" "${rate:-0}" "${edges:-0}" \
    "${features:-0}" "${corpus:-0}" "$crashes" "$leaks" "$timeouts" "$ooms" >>"$out/fuzz-summary.csv"
  printf '%-7s %9s %12s %9s %7s %9s %7s %s/%s/%s/%s\n' "$t" "$seconds" "${runs:-0}" "${rate:-0}" "${edges:-0}" \
    "${features:-0}" "${corpus:-0}" "$crashes" "$leaks" "$timeouts" "$ooms"
  if ((crashes + leaks + timeouts + ooms)); then
    status=1
    echo "fuzz: $t found a problem; its input is in $art/ (last lines of $log):"
    { grep -E 'ERROR|SUMMARY|==[0-9]+==' "$log" || true; } | head -n 8
  fi
done
echo "fuzz: summary in $out/fuzz-summary.csv"
if ((status)); then echo "fuzz: FAILED"; exit 1; fi
echo "fuzz: 0 crashes, 0 leaks, 0 timeouts, 0 out-of-memory"
