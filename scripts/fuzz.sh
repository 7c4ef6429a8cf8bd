#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Builds the libFuzzer targets (scripts/build_sanitize.sh: clang + ASan/UBSan) and runs each
# for N seconds (default 60) on a fresh corpus seeded from the unit-test writers. Usage: scripts/fuzz.sh [seconds]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
scripts/setup.sh
scripts/build_sanitize.sh  # nothing to do after scripts/test.sh, which built the same tree
for target in build/sanitize/fuzz/*_fuzz; do
  name=$(basename "$target")
  corpus=$(mktemp -d "/tmp/tofnav_${name}_XXXX")
  echo "== $name for ${seconds}s =="
  log="$corpus.log"
  dict=()
  [ -f "fuzz/${name%_fuzz}.dict" ] && dict=(-dict="fuzz/${name%_fuzz}.dict")
  if ! "$target" "${dict[@]}" -max_total_time="$seconds" -print_final_stats=1 -rss_limit_mb=4096 "$corpus" \
      >"$log" 2>&1; then
    tail -n 60 "$log" >&2
    echo "$name found a crash (reproducer: crash-* in $(pwd))" >&2
    exit 1
  fi
  grep -E '^stat::(number_of_executed_units|peak_rss_mb)' "$log" || true
  rm -rf "$corpus" "$log"
done
