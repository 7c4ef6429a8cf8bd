#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# The whole test suite: set-up, format check, layer, one-definition (ODR), file-size and citation
# checks, -Werror build + ctest, then the clang ASan+UBSan build (shared with the fuzzers) + ctest.
# The end-to-end runs (label slow) run in the optimised pass only. Each phase prints its duration.
# The sanitizer pass runs the unit tests of the modules that read bytes from outside (files,
# sockets, JSON) and builds every fuzz target; --full runs every module's unit tests under the
# sanitizers too (about 11 more minutes on 2 cores: CI's 45 minutes cannot hold both builds whole).
# Usage: scripts/test.sh [--quick | --full]  (--quick: skip the sanitizer pass)
set -euo pipefail
cd "$(dirname "$0")/.."
mode=${1:-}
case "$mode" in
  "" | --quick | --full) ;;
  *) echo "usage: scripts/test.sh [--quick | --full]" >&2; exit 2 ;;
esac
scripts/setup.sh

echo "== clang-format (v14) =="
git ls-files '*.cpp' '*.hpp' | xargs clang-format-14 --dry-run -Werror

echo "== layer, one-definition, size and citation checks =="
.ci/check_layers.sh
.ci/check_odr.sh
.ci/check_sizes.sh
.ci/check_citations.sh

phase_start=$(date +%s)
phase() {  # prints how long the previous phase took, then the next phase's title
  local now
  now=$(date +%s)
  echo "== (previous phase: $((now - phase_start)) s) $* =="
  phase_start=$now
}

phase "-Werror build"
scripts/build.sh werror -DCMAKE_BUILD_TYPE=Release -DTOFNAV_WERROR=ON -DTOFNAV_BUILD_BENCH=ON
phase "-Werror ctest"
ctest --test-dir build/werror --output-on-failure -j2 --timeout 900

if [ "$mode" != "--quick" ]; then
  modules="core;io;mesh;recording;volume;sensor;stream;report;casefile;scenario"
  [ "$mode" = "--full" ] && modules=""
  phase "AddressSanitizer + UndefinedBehaviorSanitizer build (clang, shared with the fuzzers;" \
        "unit tests of: ${modules:-every module})"
  scripts/build_sanitize.sh "-DTOFNAV_TEST_MODULES=$modules"
  phase "AddressSanitizer + UndefinedBehaviorSanitizer ctest"
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    LSAN_OPTIONS="suppressions=$PWD/.ci/lsan.supp:print_suppressions=0" \
    ctest --test-dir build/sanitize --output-on-failure -j2 -LE slow --timeout 600
fi
phase "done"
echo "== all tests passed =="
