#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Configures and builds tofnav into build/<name>. Usage: scripts/build.sh <name> [cmake args...]
set -euo pipefail
cd "$(dirname "$0")/.."
name=${1:-release}
shift || true
launcher=()
# A compiler cache when the machine has one (developer machines); without one (CI, a cold build
# every time), precompiled headers and unity batches instead (TOFNAV_PCH, TOFNAV_UNITY:
# cmake/tofnav_targets.cmake, docs/benchmarks.md "Build").
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
else
  launcher=(-DTOFNAV_PCH=ON -DTOFNAV_UNITY=ON)
fi
cmake -S . -B "build/$name" -G Ninja "${launcher[@]}" "$@" >/dev/null
ninja -C "build/$name"
