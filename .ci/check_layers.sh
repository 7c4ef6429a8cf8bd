#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Fails when a module includes a module that ARCHITECTURE.md section 5 does not allow.
set -euo pipefail
cd "$(dirname "$0")/.."

declare -A allowed=(
  [core]="core"
  [sensor]="sensor core"
  [sim]="sim sensor core"
  [markers]="markers sensor core"
  [tracking]="tracking markers sensor core"
  [registration]="registration core"
  [fusion]="fusion sensor core"
  [imaging]="imaging fusion sensor core"
  [correction]="correction markers registration sensor core"
  [navigation]="navigation tracking correction fusion imaging registration markers sensor core"
  [io]="io navigation sim tracking correction fusion imaging registration markers sensor core"
  [stream]="stream io navigation sim tracking correction fusion imaging registration markers sensor core"
  [report]="report io core"
)

status=0
for dir in src/tofnav/*/; do
  module=$(basename "$dir")
  if [ -z "${allowed[$module]+x}" ]; then
    echo "check_layers: module '$module' is not in the dependency graph" >&2
    status=1
    continue
  fi
  while IFS=: read -r file _ include; do
    used=$(sed -E 's|.*"tofnav/([a-z_]+)/.*|\1|' <<<"$include")
    # Tests may also use the simulator.
    if [[ "$file" == *_test.cpp && "$used" == sim ]]; then continue; fi
    if ! grep -qw "$used" <<<"${allowed[$module]}"; then
      echo "check_layers: $file includes tofnav/$used/ (not allowed for $module)" >&2
      status=1
    fi
  done < <(grep -rn '#include "tofnav/' "$dir" || true)
done
# Only stream/ may include OpenIGTLink headers.
if grep -rln '#include <igtl' src --include='*.?pp' | grep -v '^src/tofnav/stream/'; then
  echo "check_layers: OpenIGTLink headers outside src/tofnav/stream" >&2
  status=1
fi
exit $status
