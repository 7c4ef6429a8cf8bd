#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Builds the libFuzzer targets (scripts/build_sanitize.sh: clang + ASan/UBSan) and runs each on a
# fresh corpus seeded from the unit-test writers, either for N seconds each or within a total
# budget split equally over the targets (never under the minimum per target, so with many
# targets the total can exceed the budget; the split is printed first).
# Usage: scripts/fuzz.sh [seconds per target]            (default 60)
#        scripts/fuzz.sh --total SECONDS [--min SECONDS]  (minimum per target: default 5)
set -euo pipefail
cd "$(dirname "$0")/.."
usage() {
  echo "usage: scripts/fuzz.sh [seconds per target] | --total SECONDS [--min SECONDS]" >&2
  exit 2
}
is_count() { [[ "$1" =~ ^[0-9]+$ && "$1" -ge 1 ]]; }
seconds=60
total=""
minimum=5
while [ $# -gt 0 ]; do
  case "$1" in
    --total) [ $# -ge 2 ] && is_count "$2" || usage; total=$2; shift 2 ;;
    --min) [ $# -ge 2 ] && is_count "$2" || usage; minimum=$2; shift 2 ;;
    -h | --help) usage ;;
    *) is_count "$1" || usage; seconds=$1; shift ;;
  esac
done

scripts/setup.sh
scripts/build_sanitize.sh  # nothing to do after scripts/test.sh, which built the same tree
targets=(build/sanitize/fuzz/*_fuzz)
[ -x "${targets[0]}" ] || { echo "fuzz: no targets in build/sanitize/fuzz" >&2; exit 1; }
if [ -n "$total" ]; then
  seconds=$((total / ${#targets[@]}))
  [ "$seconds" -ge "$minimum" ] || seconds=$minimum
  echo "== fuzz budget: ${total} s over ${#targets[@]} targets: ${seconds} s each" \
       "(minimum ${minimum} s; $((seconds * ${#targets[@]})) s of fuzzing) =="
fi

fuzz_start=$(date +%s)
for target in "${targets[@]}"; do
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
echo "== fuzzing: ${#targets[@]} targets in $(($(date +%s) - fuzz_start)) s =="
