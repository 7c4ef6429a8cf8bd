#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# The whole test suite: set-up, format check, -Werror build + ctest, ASan+UBSan build + ctest,
# layer and file-size checks. The end-to-end runs (label slow) run in the optimised pass only.
# Usage: scripts/test.sh [--quick]  (--quick: skip the sanitizer pass)
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh

echo "== clang-format (v14) =="
git ls-files '*.cpp' '*.hpp' | xargs clang-format-14 --dry-run -Werror

echo "== layer and size checks =="
.ci/check_layers.sh
.ci/check_sizes.sh

echo "== -Werror build + ctest =="
scripts/build.sh werror -DCMAKE_BUILD_TYPE=Release -DTOFNAV_WERROR=ON -DTOFNAV_BUILD_BENCH=ON
ctest --test-dir build/werror --output-on-failure -j2

if [ "${1:-}" != "--quick" ]; then
  echo "== AddressSanitizer + UndefinedBehaviorSanitizer build + ctest =="
  scripts/build.sh asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTOFNAV_WERROR=ON -DTOFNAV_SANITIZE=ON
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ctest --test-dir build/asan --output-on-failure -j2 -LE slow
fi
echo "== all tests passed =="
