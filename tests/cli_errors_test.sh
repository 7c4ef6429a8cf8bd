#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# The CLI turns bad input into one clear line on stderr and a non-zero exit, never a crash.
# Usage: cli_errors_test.sh <path to tofnav>
set -uo pipefail
tofnav=$1
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
failures=0

expect_failure() {  # expect_failure <what stderr must contain> <args...>
  local needle=$1
  shift
  "$tofnav" "$@" >"$scratch/out" 2>"$scratch/err"
  local rc=$?
  if [ $rc -eq 0 ] || [ $rc -ge 128 ]; then
    echo "FAIL: tofnav $* exited $rc (expected a clean failure)"
    failures=$((failures + 1))
  elif ! grep -qF -- "$needle" "$scratch/err"; then
    echo "FAIL: tofnav $*: stderr lacks '$needle':"
    cat "$scratch/err"
    failures=$((failures + 1))
  fi
}

expect_failure "unknown subcommand" no-such-command
expect_failure "$scratch/missing.bin" info "$scratch/missing.bin"
head -c 1000 /dev/urandom >"$scratch/random.bin"
expect_failure "HL2SSV23" info "$scratch/random.bin"
printf 'HL2SSV23\xd4\x0e' >"$scratch/truncated.bin"
expect_failure "truncated.bin" info "$scratch/truncated.bin"
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n2\n' \
  >"$scratch/short.ply"
expect_failure "short.ply" info "$scratch/short.ply"
expect_failure "not an AHAT recording" convert "$scratch/random.bin" "$scratch/out_folder" --to stream-recorder
expect_failure "$scratch/missing.nrrd" skin "$scratch/missing.nrrd" --out "$scratch/skin.ply"
expect_failure "--fiducials TOOL IMAGE" register --out "$scratch/t.json"
expect_failure "short.ply" register "$scratch/short.ply" "$scratch/short.ply" --out "$scratch/t.json"
expect_failure "tofnav register: error: --method paper: the paper's ICP starts from the user's coarse placement in 3D Slicer; give it as --guess T (a tool_from_image transform file)" \
  register "$scratch/short.ply" "$scratch/short.ply" --out "$scratch/t.json" --method paper
expect_failure "--method: Paper not in {tofnav,paper}" reconstruct "$scratch/random.bin" \
  --calibration "$scratch" --tool "$scratch/t.json" --out "$scratch/s.ply" --method Paper
printf '{"markups":[{"type":"Line"}]}' >"$scratch/plan.mrk.json"
expect_failure "exactly 2 defined control points" register "$scratch/short.ply" "$scratch/short.ply" \
  --out "$scratch/t.json" --plan "$scratch/plan.mrk.json"
printf '{"name": "pair", "markers": [[0, 0, 0], [50, 0, 0]]}' >"$scratch/pair.json"
expect_failure "invalid tool" track "$scratch/random.bin" --tool "$scratch/pair.json" --out "$scratch/p.csv"
expect_failure "not an AHAT recording" tool-define "$scratch/random.bin" --out "$scratch/t.json"
printf 'frame,tool\n1,a\n' >"$scratch/bad_poses.csv"
expect_failure "bad_poses.csv" evaluate tracking "$scratch/bad_poses.csv" --truth "$scratch/missing.json"
expect_failure "unknown evaluator" evaluate no-such-thing
expect_failure "--cyclic-period-mm and --plate-radius-mm go together" fit-marker-error \
  "$scratch/random.bin" --tool "$scratch/pair.json" --out "$scratch/f.json" --cyclic-period-mm 351.7
expect_failure "--smoothing" fit-marker-error "$scratch/random.bin" --tool "$scratch/pair.json" --out "$scratch/f.json" --smoothing abc
printf '{"format": "tofnav-marker-range-error", "knots_mm": [2, 1]}' >"$scratch/frf.json"
printf '{"name": "tri", "markers": [[0, 0, 0], [50, 0, 0], [0, 60, 0]]}' >"$scratch/tri.json"
expect_failure "frf.json" track "$scratch/random.bin" --tool "$scratch/tri.json" --marker-error "$scratch/frf.json" --out "$scratch/p.csv"
printf '{"format": "tofnav-depth-model", "version": 1}' >"$scratch/model.json"
expect_failure "model.json" correct "$scratch/random.bin" --calibration "$scratch" \
  --depth-model "$scratch/model.json" --out "$scratch/c.bin"
expect_failure "calibration folder" evaluate depth "$scratch/random.bin" --truth "$scratch" \
  --calibration "$scratch"
expect_failure "calibration folder" evaluate materials "$scratch/random.bin" --truth "$scratch" \
  --calibration "$scratch"
expect_failure "--angle-bin-deg" evaluate materials "$scratch/random.bin" --truth "$scratch" \
  --angle-bin-deg 0
expect_failure "HL2SSV23" reconstruct "$scratch/random.bin" --tool "$scratch/none.json" \
  --out "$scratch/s.ply" --calibration "$scratch"
expect_failure "--roi" reconstruct "$scratch/random.bin" --tool t.json --out s.ply --roi 1,2,3
expect_failure "--head-region" reconstruct "$scratch/random.bin" --tool t.json --out s.ply \
  --head-region maybe
expect_failure "short.ply" evaluate reconstruction "$scratch/short.ply" --truth "$scratch"
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n' >"$scratch/tri.ply"
expect_failure "truth.json" evaluate reconstruction "$scratch/tri.ply" --truth "$scratch"
"$tofnav" info --help >/dev/null || { echo "FAIL: info --help"; failures=$((failures + 1)); }

printf '{"name": "R", "markers": [[0,0,0],[50,0,0],[0,60,0],[30,30,20]]}' >"$scratch/ref.json"
printf '{"target_frame": "tool", "source_frame": "image", "target_from_source": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}' >"$scratch/reg.json"
printf '{"markups":[{"type":"Line","controlPoints":[{"position":[0,0,0]},{"position":[0,0,50]}]}]}' >"$scratch/line.mrk.json"
expect_failure "tcp://127.0.0.1:1" navigate hl2ss://127.0.0.1:1 --tool "$scratch/ref.json" \
  --registration "$scratch/reg.json" --plan "$scratch/line.mrk.json" --no-igtl
expect_failure "bad port" navigate hl2ss://host:x --tool "$scratch/ref.json" \
  --registration "$scratch/reg.json" --plan "$scratch/line.mrk.json"
expect_failure "HL2SSV23" navigate "$scratch/random.bin" --tool "$scratch/ref.json" \
  --registration "$scratch/reg.json" --plan "$scratch/line.mrk.json" --no-igtl
expect_failure "expected HOST[:PORT]" navigate "$scratch/random.bin" --tool "$scratch/ref.json" \
  --registration "$scratch/reg.json" --plan "$scratch/line.mrk.json" --no-igtl --hololens hl:x
# tofnav verify (docs/navigation.md 7): a pointer without a tip, no landmark, a bad limit.
printf '{"markups":[]}' >"$scratch/none.mrk.json"
printf '{"markups":[{"type":"Fiducial","controlPoints":[{"label":"nasion","position":[0,-90,0]}]}]}' \
  >"$scratch/lm.mrk.json"
expect_failure "tofnav verify: error: --pointer $scratch/ref.json has no pivot-calibrated tip (tip_mm): calibrate it with tofnav pivot first" \
  verify "$scratch/random.bin" --tool "$scratch/ref.json" --registration "$scratch/reg.json" \
  --pointer "$scratch/ref.json" --landmarks "$scratch/lm.mrk.json" --no-igtl
printf '{"name": "P", "markers": [[0,0,0],[50,0,0],[0,60,0],[30,30,20]], "tip_mm": [0,-150,0]}' \
  >"$scratch/pointer.json"
expect_failure "tofnav verify: error: $scratch/none.mrk.json: no defined control point" \
  verify "$scratch/random.bin" --tool "$scratch/ref.json" --registration "$scratch/reg.json" \
  --pointer "$scratch/pointer.json" --landmarks "$scratch/none.mrk.json" --no-igtl
expect_failure "--pass-mm" verify "$scratch/random.bin" --tool "$scratch/ref.json" \
  --registration "$scratch/reg.json" --pointer "$scratch/pointer.json" \
  --landmarks "$scratch/lm.mrk.json" --no-igtl --pass-mm -1
expect_failure "--verify needs --instrument with a pivot-calibrated tip (tip_mm)" navigate \
  "$scratch/random.bin" --tool "$scratch/ref.json" --registration "$scratch/reg.json" \
  --plan "$scratch/line.mrk.json" --verify "$scratch/lm.mrk.json" --no-igtl
expect_failure "not an AHAT recording" pivot "$scratch/random.bin" --tool "$scratch/tri.json" \
  --reference "$scratch/ref.json" --out "$scratch/instrument.json"
printf 'timestamp_s,status\n1.0,tracking\n' >"$scratch/nav.csv"
expect_failure "not a tofnav navigate CSV" evaluate guidance "$scratch/nav.csv" --truth "$scratch"
mkdir -p "$scratch/nodemo"
expect_failure "$scratch/nodemo/demo.json" report "$scratch/nodemo"
printf '{"format": "other"}' >"$scratch/nodemo/demo.json"
expect_failure "not a tofnav demo summary" report "$scratch/nodemo"
# A sphere sunk 3.1 mm into the phantom's scalp (its crown at z = 110 mm with image = world): refused
# with one line naming the tool and the marker, nothing written (docs/simulator.md section 6.11).
cat >"$scratch/sunk.json" <<'JSON'
{"name": "sunk", "frames": 1, "patient": {"head": "phantom", "ct": {"write": false}},
 "tools": [{"name": "reference_left", "markers": [
   {"shape": "sphere", "diameter_mm": 11.5, "centre_mm": [30, 0, 200]},
   {"shape": "sphere", "diameter_mm": 11.5, "centre_mm": [-30, 0, 200]},
   {"shape": "sphere", "diameter_mm": 11.5, "centre_mm": [0, 0, 112.65]}]}]}
JSON
expect_failure "tofnav simulate: error: scenario: tool 'reference_left' marker 2 (sphere, 11.5 mm) intersects the head surface by 3.1 mm" \
  simulate "$scratch/sunk.json" --out "$scratch/sunk_out" -q
[ -e "$scratch/sunk_out" ] && { echo "FAIL: simulate wrote $scratch/sunk_out for a sunk marker"; failures=$((failures + 1)); }
[ $failures -eq 0 ] && echo "all CLI error checks passed"
exit $failures
