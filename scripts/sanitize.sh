#!/usr/bin/env bash
# Builds the unit tests with AddressSanitizer + UndefinedBehaviorSanitizer into build-asan/ and runs them
# (ctest label "unit"; the scenarios, label "scenario", are too slow under ASan). Any sanitizer report fails the
# test that produced it. About 8 to 12 minutes on 2 cores from scratch, a minute or two when rebuilt.
#   scripts/sanitize.sh            ASan + UBSan (+ LeakSanitizer), label unit, then label fault
#   scripts/sanitize.sh --tsan     ThreadSanitizer on the threaded filter tests, into build-tsan/
# SANITIZE_EXCLUDE: ctest -E regex of tests skipped (default: the slow renderer image comparisons).
# -g1: line tables only, which the reports need; full -g made build-asan/ 6 GB (CI disk).
# Environment: JOBS (default: nproc, at most 2 here), BUILD_DIR, CC/CXX (default gcc; clang works too).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
jobs=${JOBS:-$(nproc)}
supp=$root/tests/sanitizers

if [[ "${1:-}" == "--tsan" ]]; then
  build=${BUILD_DIR:-build-tsan}
  # TSan cannot share a process with ASan, so STVL_SANITIZE stays OFF and -fsanitize=thread goes on every flag.
  # Only the filter module and its tests are built: they are the only ones that start threads.
  cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSTVL_CUDA=OFF -DSTVL_MODULES=filter \
    -DCMAKE_CXX_FLAGS="-fsanitize=thread -fno-omit-frame-pointer" \
    -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=thread" >/dev/null
  cmake --build "$build" -j"$jobs" --target test_filter regression_filter
  export TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1 suppressions=$supp/tsan.supp ${TSAN_OPTIONS:-}"
  ctest --test-dir "$build" -L unit --output-on-failure -j1 --timeout 600
  exit 0
fi

build=${BUILD_DIR:-build-asan}
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g1" -DSTVL_SANITIZE=ON \
  -DSTVL_CUDA=OFF >/dev/null
cmake --build "$build" -j"$jobs"

# detect_leaks: LSan runs at exit; the suppressions name leaks inside Mesa/MuJoCo/ROS that we cannot fix.
export ASAN_OPTIONS="detect_leaks=1 abort_on_error=0 halt_on_error=1 strict_string_checks=1 detect_stack_use_after_return=1 check_initialization_order=1 strict_init_order=1 ${ASAN_OPTIONS:-}"
export LSAN_OPTIONS="suppressions=$supp/lsan.supp print_suppressions=0 ${LSAN_OPTIONS:-}"
export UBSAN_OPTIONS="print_stacktrace=1 halt_on_error=1 suppressions=$supp/ubsan.supp ${UBSAN_OPTIONS:-}"
# Mesa's llvmpipe spawns threads per context; one is plenty under ASan.
export LP_NUM_THREADS=${LP_NUM_THREADS:-1}

status=0
# Full-resolution image comparisons on llvmpipe take over 10 min each under ASan; they run in the normal build.
exclude=${SANITIZE_EXCLUDE-Renderer\.MatchesRayCasts|EglAndOsmesaGiveTheSameImage}
ctest --test-dir "$build" -L unit ${exclude:+-E "$exclude"} --output-on-failure -j"$jobs" --timeout 300 || status=1
if ctest --test-dir "$build" -N -L fault | grep -q "Total Tests: [1-9]"; then
  # intercept_tls_get_addr=0: at the exit of a run that wrote a bag under ctest, LeakSanitizer's tracer read a
  # bogus dynamic-TLS range of the main thread ("DTLS 13 at 0x26da-0x18000037dc", "Tracer caught signal 11") and
  # the run exited 1 instead of its own code; without tracking dynamic TLS the leak check runs and passes.
  ASAN_OPTIONS="$ASAN_OPTIONS intercept_tls_get_addr=0" STVL_FAULT_SIGNAL_LIMIT_S=${STVL_FAULT_SIGNAL_LIMIT_S:-3} \
    ctest --test-dir "$build" -L fault --output-on-failure -j1 --timeout 300 || status=1
fi
exit $status
