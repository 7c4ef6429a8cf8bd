#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# The one sanitizer build (clang-14, AddressSanitizer + UndefinedBehaviorSanitizer) into
# build/sanitize: the unit tests and the libFuzzer targets share it, so CI compiles the
# libraries with sanitizers once. -O1 (ASan's advice) compiles fastest with usable speed; -g1 (line
# tables) is enough for the sanitizers' stack traces.
# Usage: scripts/build_sanitize.sh [extra cmake args...]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh sanitize -DCMAKE_C_COMPILER=clang-14 -DCMAKE_CXX_COMPILER=clang++-14 \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
  -DTOFNAV_SANITIZE=ON -DTOFNAV_BUILD_FUZZ=ON "$@"
