#!/usr/bin/env bash
# README command 2 (and CI): install what is missing, build Release and run every test,
# then build with AddressSanitizer + UndefinedBehaviorSanitizer and run every test again.
# Last, a short fuzzing run (tools/fuzz.sh: clang-14 libFuzzer, ASan+UBSan; 60 s, all targets at once).
#   LMB_TEST_SANITIZE=0 skips the sanitizer pass (for a quick local run).
#   LMB_TEST_FUZZ_SECONDS: the fuzzing run's length (default 60; 0 skips it).
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)

tools/setup.sh build
echo "test: Release build"
(cd build && ctest --output-on-failure -j"$jobs")

if [ "${LMB_TEST_SANITIZE:-1}" != 0 ]; then
  tools/setup.sh build-asan -DLMB_SANITIZE=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo
  echo "test: ASan+UBSan build"
  (cd build-asan && ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
     ctest --output-on-failure -j"$jobs")
fi
fuzz_seconds=${LMB_TEST_FUZZ_SECONDS:-60}
if [ "$fuzz_seconds" != 0 ]; then
  echo "test: fuzzing, ${fuzz_seconds} s"
  tools/fuzz.sh "$fuzz_seconds"
fi
echo "test: all passed"
