#!/usr/bin/env bash
# Builds the whole test suite with AddressSanitizer + UndefinedBehaviorSanitizer (LeakSanitizer
# included) into ${PLDVO_ASAN_BUILD_DIR:-build-asan} and runs every test; any sanitizer report
# fails its test. Usage: scripts/sanitize.sh [ctest args...]   (e.g. -R Trajectory)
# ${PLDVO_ASAN_FLAGS:--O1 -g1} are the compile flags (.ci/run passes -O2 -g0) and
# ${PLDVO_ASAN_CXX:-clang++} the compiler (clang builds the suite 20-30% faster than g++, and the
# fuzzers need it anyway; PLDVO_ASAN_CXX=g++ gives gcc's sanitizers). Prints the build
# and test wall times. ${PLDVO_ASAN_STACK_USE_AFTER_RETURN:-1}: ASan's detect_stack_use_after_return
# (.ci/run passes 0). See docs/reliability.md.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh
build=${PLDVO_ASAN_BUILD_DIR:-build-asan}
# -O1: ASan's recommended level (fast enough to run, readable stack traces); -g1: line tables
# for symbolized reports at a fraction of -g's compile and link cost (-g0: function names only).
# No -DNDEBUG: assertions (Eigen's index and size checks, glog DCHECKs) stay on, so they are
# checked here too. The tests see PLDVO_SANITIZE defined (tests/CMakeLists.txt). Precompiled
# headers: 15% less build time; the README's build, without them, checks the includes.
start=$SECONDS
cmake -S . -B "$build" -G Ninja \
  -DCMAKE_CXX_COMPILER="${PLDVO_ASAN_CXX:-clang++}" \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="${PLDVO_ASAN_FLAGS:--O1 -g1}" \
  -DPLDVO_SANITIZE=ON -DPLDVO_BUILD_TESTS=ON -DPLDVO_BUILD_BENCHMARKS=OFF \
  -DPLDVO_BUILD_FUZZERS=OFF -DPLDVO_PRECOMPILE_HEADERS=ON >/dev/null
cmake --build "$build" -j "$(nproc)"
echo "sanitize: build $((SECONDS - start)) s"

# Every report is fatal: ASan and LSan exit non-zero at the first error (halt_on_error), UBSan
# too (the build uses -fno-sanitize-recover=undefined; halt_on_error covers the rest).
export ASAN_OPTIONS="halt_on_error=1:abort_on_error=0:detect_leaks=1:detect_stack_use_after_return=${PLDVO_ASAN_STACK_USE_AFTER_RETURN:-1}:strict_string_checks=1:check_initialization_order=1:detect_odr_violation=2:exitcode=23"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:report_error_type=1"
export LSAN_OPTIONS="exitcode=23:suppressions=$PWD/scripts/lsan_suppressions.txt:print_suppressions=0"
start=$SECONDS
status=0
ctest --test-dir "$build" -j "$(nproc)" --output-on-failure "$@" || status=$?
echo "sanitize: tests $((SECONDS - start)) s"
exit $status
