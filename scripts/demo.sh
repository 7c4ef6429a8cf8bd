#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# The main job, until `tofnav demo` exists: installs and builds, simulates a short head-worn
# AHAT recording of the paper's head-identification set-up in the exact hl2ss format, then reads
# it back with the real readers. Usage: scripts/demo.sh [output folder] (default: out/demo)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/demo}
scripts/setup.sh
scripts/build.sh release -DCMAKE_BUILD_TYPE=Release >/dev/null
tofnav=build/release/apps/cli/tofnav
"$tofnav" simulate head-identification --frames 90 --seed 1 --truth-depth --out "$out"
"$tofnav" info "$out/rm_depth_ahat.bin"
"$tofnav" info "$out/calibration"
"$tofnav" info "$out/ct.nrrd"
"$tofnav" info "$out/skin_truth.ply"
"$tofnav" convert "$out/rm_depth_ahat.bin" "$out/stream_recorder" --to stream-recorder \
  --calibration "$out/calibration" --quiet
"$tofnav" info "$out/stream_recorder"
