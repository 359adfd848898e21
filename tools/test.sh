#!/usr/bin/env bash
# README command 2 (and CI): install what is missing, build Release and run every test,
# then build with AddressSanitizer + UndefinedBehaviorSanitizer and run every test again.
# Last, a short fuzzing run (tools/fuzz.sh: clang-14 libFuzzer, ASan+UBSan; 60 s, all targets at once).
#   LMB_TEST_SANITIZE=0 skips the sanitizer pass (for a quick local run).
#   LMB_TEST_FUZZ_SECONDS: the fuzzing run's length (default 60; 0 skips it).
# Each next build runs beside the tests before it, at the lowest CPU priority (nice 19): it
# takes the cores the tests leave idle (a browser loading a page, a watch polling, the last
# test of a pass running alone) and gets about 1.5% of a core while the tests want both, so
# the tests' timings barely move. Its log is printed when it is waited for. The fuzz build
# runs beside only when its packages (clang-14, libFuzzer) are installed: installing asks for
# sudo, which a background job cannot (tools/fuzz.sh then builds it in the foreground).
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)
sanitize=${LMB_TEST_SANITIZE:-1}
fuzz_seconds=${LMB_TEST_FUZZ_SECONDS:-60}

# start_beside NAME COMMAND...: runs COMMAND niced in the background, its output in
# build/NAME-beside.log; wait_beside NAME waits for it and prints that log (a failure exits).
# A failing test pass stops the script and the build beside it (its own process group).
declare -A beside_pid
trap 'for p in "${beside_pid[@]}"; do kill -- -"$p" 2>/dev/null || true; done' EXIT
start_beside() {
  local name=$1
  shift
  setsid -w nice -n 19 "$@" >"build/$name-beside.log" 2>&1 &
  beside_pid[$name]=$!
}
wait_beside() {
  local rc=0
  wait "${beside_pid[$1]}" || rc=$?
  unset "beside_pid[$1]"
  cat "build/$1-beside.log"
  if [ "$rc" != 0 ]; then
    echo "test: the $1 build failed (exit $rc)"
    exit 1
  fi
}

tools/setup.sh build
[ "$sanitize" != 0 ] && start_beside build-asan tools/setup.sh build-asan -DLMB_SANITIZE=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo
echo "test: Release build"
(cd build && ctest --output-on-failure -j"$jobs")

if [ "$sanitize" != 0 ]; then
  wait_beside build-asan
  fuzz_beside=0
  if [ "$fuzz_seconds" != 0 ] && LMB_FUZZ_PACKAGES_INSTALLED=1 tools/fuzz.sh; then
    fuzz_beside=1
    start_beside build-fuzz env LMB_FUZZ_BUILD_ONLY=1 tools/fuzz.sh
  fi
  echo "test: ASan+UBSan build"
  # intercept_tls_get_addr=0: the runtime's interceptor misreads some dynamic TLS blocks (those
  # of the dlopened image module's libraries) and LeakSanitizer then crashed at exit now and then;
  # without it those blocks are still found, through each thread's TLS vector (docs/testing.md)
  (cd build-asan && ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:intercept_tls_get_addr=0 \
     UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 ctest --output-on-failure -j"$jobs")
fi
if [ "$fuzz_seconds" != 0 ]; then
  [ "${fuzz_beside:-0}" = 1 ] && wait_beside build-fuzz
  echo "test: fuzzing, ${fuzz_seconds} s"
  tools/fuzz.sh "$fuzz_seconds"
fi
echo "test: all passed"
