#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# What each hl2ss stream profile costs (docs/suite.md, "Stream profiles"): the demo (seed 1) and
# four suite cases (spheres, discs, a CT head, an MR head) run on ZDEPTH+RAW (the reference),
# ZDEPTH+H265 at the client's default bitrate and at 4x and 16x, ZDEPTH+H264 (Main) and
# SAME+H265 at their defaults; prints one markdown table with every stage's figure and the
# bitrate measured on the stream. Usage: scripts/profile_costs.sh TOFNAV OUT_DIR [FRAMES_SCALE]
set -euo pipefail
tofnav=$1
out=$2
scale=${3:-1}
mkdir -p "$out"
configs=("zdepth" "zdepth+h265" "zdepth+h265:3774872" "zdepth+h265:15099488" "zdepth+h264"
         "same+h265")
cases=(--only phantom-spheres --only phantom-discs --only ct-spheres --only mr-discs)
for config in "${configs[@]}"; do
  profile=${config%%:*}
  args=(--profile "$profile")
  [ "$config" != "$profile" ] && args+=(--bitrate-bps "${config#*:}")
  name=${config//[:+]/_}
  if [ ! -s "$out/demo_$name.json" ]; then
    echo "== demo $config ==" >&2
    "$tofnav" demo --seed 1 --frames-scale "$scale" "${args[@]}" --out "$out/demo_$name" --json -q \
      >"$out/demo_$name.tmp" && mv "$out/demo_$name.tmp" "$out/demo_$name.json"
  fi
  if [ ! -s "$out/suite_$name.json" ]; then
    echo "== suite cases $config ==" >&2
    "$tofnav" evaluate suite default "${cases[@]}" "${args[@]}" --out "$out/suite_$name" --json -q \
      >"$out/suite_$name.tmp" || true
    mv "$out/suite_$name.tmp" "$out/suite_$name.json"
  fi
done
/usr/bin/python3 "$(dirname "$0")/profile_costs_table.py" "$out" "${configs[@]}"
