#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# The independent oracle for the hl2ss H.264 / H.265 profiles (docs/ahat.md 3.6): a 90-frame
# simulated session recorded as SAME+H265, SAME+H264 (Main) and ZDEPTH+H265 by `tofnav simulate
# --profile`, decoded by tofnav (`tofnav convert --to raw`) and, independently, by PyAV with the
# client's mapping written from the format facts (hl2ss_h26x_oracle.py): 0 differing pixels on
# every frame. Also: `tofnav info` names the profile, bitrate and GOP; identify refuses SAME+H26x.
# Usage: h26x_oracle_test.sh TOFNAV TESTS_DIR  (exit 77: no PyAV)
set -euo pipefail
tofnav=$1
tests=$2
/usr/bin/python3 -c "import av, numpy" 2>/dev/null || { echo "PyAV (python3-av) missing: skipped"; exit 77; }
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
for profile in same+h265 same+h264 zdepth+h265; do
  "$tofnav" simulate evd-usecase --frames 90 --profile "$profile" --out "$scratch/$profile" -q
  "$tofnav" convert "$scratch/$profile/rm_depth_ahat.bin" "$scratch/$profile/decoded.bin" --to raw -q
  /usr/bin/python3 "$tests/hl2ss_h26x_oracle.py" "$scratch/$profile/rm_depth_ahat.bin" \
    "$scratch/$profile/decoded.bin"
done
"$tofnav" info "$scratch/zdepth+h265/rm_depth_ahat.bin" >"$scratch/info.txt"
grep -q "profile: ZDEPTH+H265_MAIN" "$scratch/info.txt"
grep -q "gop_frames: 45" "$scratch/info.txt"
grep -q "measured_gop_frames: 45" "$scratch/info.txt"
grep -q "bitrate_bps: 943718" "$scratch/info.txt"
if "$tofnav" reconstruct "$scratch/same+h265/rm_depth_ahat.bin" --calibration "$scratch/same+h265/calibration" \
     --tool x --out "$scratch/x.ply" 2>"$scratch/refused.txt"; then
  echo "reconstruct accepted SAME+H265 depth" >&2
  exit 1
fi
grep -q "its depth is SAME+H265_MAIN: 4 mm steps" "$scratch/refused.txt" || { cat "$scratch/refused.txt"; exit 1; }
echo "h26x oracle: every profile decoded identically"
