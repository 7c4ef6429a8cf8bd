#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# The main job: installs the Debian packages, builds the tofnav program alone (Release; no tests,
# benchmarks, fuzzers or Python bindings, so a newcomer waits minutes, not the whole test build),
# then runs `tofnav demo`, the paper end to end on the real head CT of Debian's
# invesalius-examples (the synthetic head without it): f_rf, identification, reconstruction,
# registration, tracking and guidance, the paper's tables beside ours, every artefact and
# report.html in the output folder (docs/demo.md). Each phase prints one line and its duration.
# Usage: scripts/demo.sh [output folder] [tofnav demo options...] (default folder: out/demo)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/demo}
shift || true

phase_start=$(date +%s)
took() { echo "demo.sh: $* ($(($(date +%s) - phase_start)) s)" >&2; phase_start=$(date +%s); }

echo "demo.sh: [1/3] set-up (Debian packages, only the missing ones)..." >&2
scripts/setup.sh
took "[1/3] set-up done"

echo "demo.sh: [2/3] building build/release/apps/cli/tofnav (Release, the program only)..." >&2
launcher=()
# A compiler cache when the machine has one; without one (a first build), precompiled headers
# and unity batches (4.4 minutes instead of 12.8 on 2 cores: docs/benchmarks.md "Build").
if command -v ccache >/dev/null && [ -z "${CCACHE_DISABLE:-}" ]; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
else
  launcher=(-DTOFNAV_PCH=ON -DTOFNAV_UNITY=ON)
fi
mkdir -p build/release
log=build/release/demo_build.log  # the compiler's output; its end is printed on failure
if ! { cmake -S . -B build/release -G Ninja "${launcher[@]}" -DCMAKE_BUILD_TYPE=Release \
         -DTOFNAV_BUILD_TESTS=OFF -DTOFNAV_BUILD_BENCH=OFF -DTOFNAV_BUILD_FUZZ=OFF \
         -DTOFNAV_BUILD_PYTHON=OFF &&
       cmake --build build/release --target tofnav; } >"$log" 2>&1; then
  tail -n 40 "$log" >&2
  echo "demo.sh: the build failed (whole log: $log)" >&2
  exit 1
fi
took "[2/3] build done"

echo "demo.sh: [3/3] tofnav demo --out $out $*" >&2
build/release/apps/cli/tofnav demo --out "$out" "$@"
took "[3/3] demo done: $out/report.html"
