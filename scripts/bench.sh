#!/usr/bin/env bash
# Builds the Google Benchmark binary in ./build and prints its table (medians, means and spreads
# of 5 repetitions). Takes a few minutes on 2 cores. Extra arguments go to the binary, e.g.
#   scripts/bench.sh --benchmark_filter='^kinematic/'
# A fresh ./build is configured as Release; an existing one keeps its build type (test.sh uses
# RelWithDebInfo, -O2), which is printed below so the table says what it measured.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/generator.sh
if [[ ! -f build/CMakeCache.txt ]]; then
  cmake -S . -B build $(generator build) -DCMAKE_BUILD_TYPE=Release -DMECHBENCH_BUILD_BENCH=ON >/dev/null
else
  cmake -S . -B build $(generator build) -DMECHBENCH_BUILD_BENCH=ON >/dev/null
fi
cmake --build build -j2 --target mechbench_bench
echo "build type: $(sed -n 's/^CMAKE_BUILD_TYPE:[A-Z]*=//p' build/CMakeCache.txt)"
echo "machine: $(lscpu | sed -n 's/^Model name: *//p' | head -1), $(nproc) CPUs"
exec build/bench/mechbench_bench --benchmark_repetitions=5 --benchmark_report_aggregates_only=true "$@"
