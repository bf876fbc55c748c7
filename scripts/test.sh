#!/usr/bin/env bash
# Builds mechbench and runs every test suite (the README's test command).
#
# CI runs the same command with MECHBENCH_WERROR=ON and MECHBENCH_SANITIZE=ON: one build that
# carries both (warnings as errors; AddressSanitizer + UndefinedBehaviorSanitizer at -O1, in
# build-sanitize/) and runs every suite once, the end-to-end report tests included; there each
# test executable runs as 8 ctest entries (gtest sharding) rather than one process per test.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/generator.sh
werror="${MECHBENCH_WERROR:-OFF}"
if [[ "${MECHBENCH_SANITIZE:-OFF}" == ON ]]; then
  dir=build-sanitize
  # clang compiles this build in about half GCC's time (Eigen at -O1 with the sanitizers);
  # GCC when clang is absent. The benchmark binary is not part of the tests.
  compiler=()
  if command -v clang++ >/dev/null; then compiler=(-DCMAKE_CXX_COMPILER=clang++); fi
  cmake -S . -B "$dir" $(generator "$dir") "${compiler[@]}" -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-g1 -O1" \
    -DMECHBENCH_SANITIZE=ON -DMECHBENCH_WERROR="$werror" -DMECHBENCH_TEST_SHARDS=8 -DMECHBENCH_BUILD_BENCH=OFF >/dev/null
  export ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
else
  dir=build
  cmake -S . -B "$dir" $(generator "$dir") -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMECHBENCH_WERROR="$werror" >/dev/null
fi
cmake --build "$dir" -j2
ctest --test-dir "$dir" --output-on-failure -j2
