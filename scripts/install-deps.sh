#!/usr/bin/env bash
# Installs mechbench's build dependencies from Debian's packages (needs root or sudo).
set -euo pipefail
pkgs=(cmake g++ clang make ninja-build libeigen3-dev libyaml-cpp-dev libcli11-dev nlohmann-json3-dev
      libgtest-dev libbenchmark-dev libbullet-dev libode-dev libsimbody-dev libmujoco-dev libqhull-dev
      libsuitesparse-dev  # KLU: the sparse LU of the index-1 matrix
      # the report: plots (gnuplot), and for its tests: the JSON Schema check, a headless
      # browser that renders report.html, GNU parallel for the sharded run
      gnuplot-nox python3-jsonschema chromium parallel)
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  echo "installing: ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}"
fi
