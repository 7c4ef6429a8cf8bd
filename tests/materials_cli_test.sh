#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# tofnav evaluate materials on a brief materials scene (three stations, 18 frames) with the true
# f_rf: the IR-tape reference plane gives each material's depth error as the truth does, and the
# materials keep the simulator's order (PLA's long subsurface delay far above nylon's).
# Usage: materials_cli_test.sh TOFNAV TESTS_DIR
set -euo pipefail
tofnav=$1
tests=$2
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
"$tofnav" simulate "$tests/scenarios/materials_brief.json" --out "$scratch/m" -q >/dev/null
# f_rf as the set-up phase would measure it: the retro curve (linear over 300-700 mm) plus wiggle,
# with the tape's entrance-angle gain.
/usr/bin/python3 "$tests/true_marker_range.py" "$scratch/m" "$scratch/frf.json"
"$tofnav" evaluate materials "$scratch/m/rm_depth_ahat.bin" --truth "$scratch/m" \
  --marker-error "$scratch/frf.json" --scenario "$tests/scenarios/materials_brief.json" -q
"$tofnav" evaluate materials "$scratch/m/rm_depth_ahat.bin" --truth "$scratch/m" \
  --marker-error "$scratch/frf.json" --scenario "$tests/scenarios/materials_brief.json" \
  --json >"$scratch/m.json"
/usr/bin/python3 - "$scratch/m.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
REF_VS_TRUTH_MM = 0.25  # reference plane (tape, f_rf applied) vs truth, per material median
MIN_PIXELS = 1000      # per sample material over the 18 frames
assert r["frames"] == 18 and r["frames_with_plane"] == 18, r["frames_with_plane"]
overall = {c["material"]: c for c in r["overall"]}
for name in ("nylon", "pla", "photopolymer"):
    c = overall[name]
    ref, true = c["vs_reference"]["median_mm"], c["vs_truth"]["median_mm"]
    print(f"{name}: vs reference {ref:.2f} mm, vs truth {true:.2f} mm, {c['vs_reference']['count']} px")
    assert c["vs_reference"]["count"] >= MIN_PIXELS, c
    assert abs(ref - true) <= REF_VS_TRUTH_MM, c
assert overall["pla"]["vs_reference"]["median_mm"] > overall["nylon"]["vs_reference"]["median_mm"] + 2.0
depths = {tuple(c["depth_mm"]) for c in r["by_depth"] if c["material"] == "nylon"}
angles = {tuple(c["angle_deg"]) for c in r["by_angle"] if c["material"] == "nylon"}
assert len(depths) >= 3 and len(angles) >= 3, (depths, angles)
PY
