#!/usr/bin/env bash
# Installs what is missing, builds, and runs the main job: every book value checked and every
# scenario's motion run through every method (the README's main command).
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build build -j2 --target mechbench
status=0
./build/harness/mechbench check || status=$?
./build/harness/mechbench run || status=$((status > $? ? status : $?))
exit $status
