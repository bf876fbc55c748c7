#!/usr/bin/env bash
# The README's main command: installs what is missing, builds, and writes the comparison report
# (book checks, every method against the reference, work–precision sweeps, stress cases) to
# ./report: report.html, results.json, results.csv, summary.md. Extra arguments go to
# `mechbench report`, e.g. `scripts/report.sh --quick` or `scripts/report.sh fourbar_free`.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/generator.sh
./scripts/install-deps.sh
cmake -S . -B build $(generator build) -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build build -j2 --target mechbench
exec ./build/harness/mechbench report --out report --jobs "$(nproc)" "$@"
