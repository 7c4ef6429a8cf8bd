#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Fails when a module includes a module that docs/architecture.md does not allow: the one
# statement of the allowed arrows (CMake's DEPENDS must not exceed it).
set -euo pipefail
cd "$(dirname "$0")/.."

declare -A allowed=(
  # foundations
  [core]="core"
  [sensor]="sensor core"
  [io]="io core"
  # stages (the paper's algorithms; no files)
  [fusion]="fusion sensor core"
  [registration]="registration core"
  [imaging]="imaging fusion sensor core"
  [markers]="markers sensor core"
  [tracking]="tracking markers sensor core"
  [correction]="correction markers registration sensor core"
  [sim]="sim sensor core"
  # formats: each depends on the file primitives and the types it reads and writes
  [mesh]="mesh io core"
  [volume]="volume io imaging fusion sensor core"
  [recording]="recording io sensor core"
  [casefile]="casefile io tracking correction imaging fusion registration markers sensor core"
  [describe]="describe recording volume mesh io imaging fusion sensor core"
  # compositions of the stages (frames through sensor/'s interface; case files for their types)
  [pipeline]="pipeline casefile io tracking correction fusion imaging registration markers sensor core"
  # the simulator's files, and comparisons with its truth
  [scenario]="scenario sim casefile recording volume mesh io tracking correction imaging fusion registration markers sensor core"
  [evaluation]="evaluation scenario pipeline sim casefile recording volume mesh io tracking correction fusion imaging registration markers sensor core"
  # the live link and the report
  [stream]="stream pipeline casefile recording mesh io tracking correction fusion imaging registration markers sensor core"
  [report]="report mesh io core"
  # test support: the remote-scene plugin's stand-in (tests and benchmarks only)
  [stream_testing]="stream_testing stream pipeline casefile recording mesh io tracking correction fusion imaging registration markers sensor core"
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
    # Tests may also build scenes with the simulator and score them against its truth, and talk
    # to the test support's stand-ins.
    if [[ "$file" == *_test.cpp && "$used" =~ ^(sim|scenario|describe|evaluation|stream_testing)$ ]]; then continue; fi
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
