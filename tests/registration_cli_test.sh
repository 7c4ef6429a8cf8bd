#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# End to end through the CLI on a simulated case: tofnav simulate -> skin (from ct.nrrd) ->
# register a moved face crop of the true skin with the plan; a vertex cap must be refused.
# Usage: registration_cli_test.sh <path to tofnav>
set -euo pipefail
tofnav=$1
here=$(dirname "$0")
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
py=/usr/bin/python3

"$tofnav" simulate evd-usecase --out "$scratch/case" --frames 1 -q >/dev/null
"$tofnav" skin "$scratch/case/ct.nrrd" --out "$scratch/skin.ply" --json >"$scratch/skin.json"
grep -q '"threshold_source": "CT default"' "$scratch/skin.json"

$py "$here/registration_cli_test.py" crop "$scratch/case/skin_truth.ply" "$scratch/face.ply" face
"$tofnav" register "$scratch/face.ply" "$scratch/skin.ply" --out "$scratch/t.json" \
  --plan "$scratch/case/plan.mrk.json" --tfm "$scratch/t.tfm" --txt "$scratch/t.txt" --json \
  >"$scratch/report.json"
grep -q '"accepted": true' "$scratch/report.json"
grep -q '^#Insight Transform File V1.0' "$scratch/t.tfm"
grep -q '^# tofnav transform tool_from_image' "$scratch/t.txt"
# CT-extracted skin (1 mm voxels, 12 HU noise) against the true mesh: sub-millimetre at targets.
$py "$here/registration_cli_test.py" check "$scratch/t.json" "$scratch/case/plan.mrk.json" 1.0

$py "$here/registration_cli_test.py" crop "$scratch/case/skin_truth.ply" "$scratch/cap.ply" vertex
set +e
"$tofnav" register "$scratch/cap.ply" "$scratch/skin.ply" --out "$scratch/cap.json" \
  --plan "$scratch/case/plan.mrk.json" -q 2>"$scratch/err"
rc=$?
set -e
[ $rc -eq 2 ] || { echo "FAIL: a vertex cap registered (exit $rc)"; exit 1; }
grep -q 'refused' "$scratch/err"
[ ! -e "$scratch/cap.json" ] || { echo "FAIL: a refused registration was written"; exit 1; }
echo "registration CLI end to end passed"
