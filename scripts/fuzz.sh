#!/usr/bin/env bash
# Builds the libFuzzer targets of tests/fuzz with clang (ASan + UBSan, coverage on every pldvo
# library) into ${PLDVO_FUZZ_BUILD_DIR:-build-fuzz} and runs each for a bounded time from a
# temporary copy of its seed corpus tests/fuzz/corpus/<name>/ (the repository is not written).
# Usage: scripts/fuzz.sh [seconds_per_target] [target...]   (default 30 s, all targets)
# A crash, sanitizer report, hang (> 5 s per input), > 2 GB RSS or a broken invariant fails the
# script; the input is kept in $build/fuzz-artifacts/. See docs/reliability.md.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-30}
shift || true
scripts/install_deps.sh
build=${PLDVO_FUZZ_BUILD_DIR:-build-fuzz}
cmake -S . -B "$build" -G Ninja \
  -DCMAKE_CXX_COMPILER=clang++ \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS="-fsanitize=fuzzer-no-link" \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" \
  -DPLDVO_SANITIZE=ON -DPLDVO_BUILD_FUZZERS=ON \
  -DPLDVO_BUILD_TESTS=OFF -DPLDVO_BUILD_BENCHMARKS=OFF -DPLDVO_PRECOMPILE_HEADERS=ON >/dev/null
cmake --build "$build" -j "$(nproc)" --target pldvo_fuzzers

targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  targets=(camera_yaml config trajectory tum_dataset kitti_dataset euroc_dataset mono_vo_dataset)
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
artifacts="$build/fuzz-artifacts"
mkdir -p "$artifacts"
export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1:abort_on_error=0"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
failed=()
for name in "${targets[@]}"; do
  corpus="$work/$name"
  mkdir -p "$corpus"
  cp -r "tests/fuzz/corpus/$name/." "$corpus/"
  log="$work/$name.log"
  echo "fuzz: $name for ${seconds} s"
  if "$build/tests/fuzz/${name}_fuzzer" "$corpus" -max_total_time="$seconds" -timeout=5 \
      -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$artifacts/$name-" \
      >"$log" 2>&1; then
    grep -E "^stat::(number_of_executed_units|new_units_added)|^#[0-9]+.*DONE" "$log" | tr '\n' ' '
    echo
  else
    failed+=("$name")
    tail -n 60 "$log"
    echo "fuzz: $name FAILED (input in $artifacts/)"
  fi
done
if [ ${#failed[@]} -ne 0 ]; then
  echo "fuzz: findings in: ${failed[*]}" >&2
  exit 1
fi
echo "fuzz: no findings in ${targets[*]}"
