#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Source files: warn above 300 lines, fail above 400 (tables in *_tables.* are exempt).
set -euo pipefail
cd "$(dirname "$0")/.."
status=0
while read -r file; do
  case "$file" in *_tables.*) continue ;; esac
  lines=$(wc -l <"$file")
  if [ "$lines" -gt 400 ]; then
    echo "check_sizes: $file has $lines lines (limit 400)" >&2
    status=1
  elif [ "$lines" -gt 300 ]; then
    echo "check_sizes: warning: $file has $lines lines (aim for under 300)" >&2
  fi
done < <(git ls-files '*.cpp' '*.hpp' '*.py')
exit $status
