#!/usr/bin/env bash
# Builds mechbench and runs every test suite (the README's test command).
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMECHBENCH_WERROR="${MECHBENCH_WERROR:-OFF}" >/dev/null
cmake --build build -j2
ctest --test-dir build --output-on-failure -j2
