#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# tofnav demo end to end on the built-in phantom at a small frame scale: one JSON object on
# stdout, every stage ok, demo.json equal to it, the artefacts present, and each stage's figures
# within tolerances loose enough for the short run (the full run's acceptance lines are in
# docs/demo.md). Usage: demo_cli_test.sh TOFNAV
set -euo pipefail
tofnav=$1
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
# Multipath off: these tolerances guard the stages under the conditions of issues 4-8. With
# multipath on (the demo's default) the demo misses several lines today (docs/demo.md); the
# outlier-proof pipeline (issue 16) is measured by the robustness suite (tests/suite_cli_test.sh).
"$tofnav" demo --out "$scratch/demo" --head phantom --frames-scale 0.35 --multipath-gain 0 \
  --stability 1 --method both --json >"$scratch/stdout.json"
/usr/bin/python3 - "$scratch/stdout.json" "$scratch/demo" <<'PY'
import json, math, os, sys
out = json.load(open(sys.argv[1]))  # stdout must be exactly one JSON object
d = sys.argv[2]
assert out == json.load(open(os.path.join(d, "demo.json"))), "stdout differs from demo.json"
assert out["format"] == "tofnav-demo" and out["version"] == 1 and out["head"] == "phantom"
stages = out["stages"]
for name in ["marker_error", "session", "depth", "reconstruction", "registration", "tracking",
             "guidance"]:
    assert stages[name]["ok"], (name, stages[name]["error"])
# Artefacts named in demo.json exist.
for name, stage in stages.items():
    for key, value in stage.items():
        if isinstance(value, str) and (key.endswith(("_ply", "_csv", "_json")) or key in ("recording",)):
            assert os.path.isfile(os.path.join(d, value)), (name, key, value)
# Tolerances for the short run (frames-scale 0.35), each with its reason:
FRF_BIAS_MM = 0.3          # issue 4: 0.2 mm on the full stage; 56 frames leave ~0.05 mm noise
HEAD_AFTER_MM = 0.8        # issue 5: 0.5 mm on 1000 frames; ~100 frames here
REDUCTION_PCT = 80.0       # issue 5: >= 90 % with the CT
RECON_MEDIAN_MM = 0.7      # issue 6: 0.3 mm; 105 frames fused (0.47 mm seen); the paper 0.46 mm
TRE_MM = 2.0               # issue 7: 1.0 mm given a 0.3 mm reconstruction
TRACK_RMS_MM = 0.6         # issue 4: 0.25 mm; 105 frames, reference_left rarely whole (0.43 mm seen)
ENTRY_MM, ANGLE_DEG = 2.0, 2.0  # issue 8: 1.0 / 1.0 with the true registration; paper 2.09 / 2.97
s = stages
assert s["marker_error"]["bias_after_max_abs_mm"] <= FRF_BIAS_MM, s["marker_error"]
assert s["marker_error"]["bias_after_max_abs_mm"] < s["marker_error"]["bias_before_max_abs_mm"]
# The sensor's cyclic error measured on the stage's plate (docs/correction.md 2.8) against the
# simulator's: 1.07 mm / +0.11 rad off on the suite's stages (400 frames, the same here); the
# plate's own terms and the phase range leave that much, a wrong sign or period gives 1+ rad.
CYCLIC_AMPLITUDE_MM, CYCLIC_PHASE_RAD = 0.2, 0.3
c = s["marker_error"]["cyclic_error"]
assert "error" not in c, c
assert abs(c["amplitude_mm"] - c["truth"]["amplitude_mm"]) <= CYCLIC_AMPLITUDE_MM, c
assert abs(math.remainder(c["phase_rad"] - c["truth"]["phase_rad"], 2 * math.pi)) <= CYCLIC_PHASE_RAD, c
frf = json.load(open(os.path.join(d, "frf.json")))
assert frf["cyclic_error"]["amplitude_mm"] == c["amplitude_mm"], frf["cyclic_error"]
assert s["depth"]["model"]["cyclic_error"]["phase_rad"] == c["phase_rad"]  # held
head = [o for o in s["depth"]["objects"] if o["target"]]
assert len(head) == 1, s["depth"]["objects"]
assert abs(head[0]["after_median_mm"]) <= HEAD_AFTER_MM, head
assert head[0]["reduction_percent"] >= REDUCTION_PCT, head
# --stability 1: the identification again without a tenth of its frames (issue 40 item 2). The
# mechanics, and a loose bound: a change of the head's corrected median over 0.3 mm from a tenth
# of ~100 frames would be a broken identification, not the instability issue 40 measures.
# The head's errors by true incidence and range (docs/correction.md 2.5): every head pixel has a
# true range, so the range bins hold them all; 15-deg and 100-mm bins in order; where the model
# leaves more than 1.0 mm in a well-filled bin (>= 1000 px) it misfits that part of the head
# (HEAD_AFTER_MM's short-run slack plus 0.2 mm for a bin's narrower view set).
BIN_AFTER_MM = 1.0
by_range, by_angle = head[0]["by_range_mm"], head[0]["by_incidence_deg"]
assert sum(b["pixels"] for b in by_range) == head[0]["pixels"], (by_range, head)
assert 0 < sum(b["pixels"] for b in by_angle) <= head[0]["pixels"], by_angle
for bins, key, width in ((by_range, "mm", 100.0), (by_angle, "deg", 15.0)):
    for a, b in zip(bins, bins[1:]):
        assert a["to_" + key] <= b["from_" + key], bins
    for b in bins:
        assert b["to_" + key] - b["from_" + key] == width, b
        if b["pixels"] >= 1000:
            assert abs(b["after_median_mm"]) <= BIN_AFTER_MM, bins
st = s["depth"]["stability"]
assert len(st["runs"]) == 1 and st["runs"][0]["left_out"] == "frame k with k % 10 == 0", st
assert abs(st["runs"][0]["head_after_median_change_mm"]) <= 0.3, st
assert st["max_C1_change_mm"] == abs(st["runs"][0]["C1_change_mm"]), st
h = s["depth"]["histogram"]
assert len(h["bin_edges_mm"]) == len(h["before"]) + 1 == len(h["after"]) + 1
assert s["reconstruction"]["median_mm"] <= RECON_MEDIAN_MM, s["reconstruction"]
assert s["registration"]["tre_mm"] <= TRE_MM, s["registration"]
for t in s["tracking"]["tools"]:
    if t["name"].startswith("reference"):
        assert t["position_rms_mm"] <= TRACK_RMS_MM and t["wrong_identities"] == 0, t
g = s["guidance"]
assert g["entry_median_mm"] <= ENTRY_MM and g["angle_median_deg"] <= ANGLE_DEG, g
assert len(g["trajectories"]) == 9, g
# The instrument as navigate shows it beside the headframe: its tip 171 mm from its markers, so
# the orientation line (0.35 deg) moves it 1.0 mm and the position line 0.3 mm: 1.5 mm.
gi = g["instrument"]
assert 0 <= gi["wrong_identities"] <= gi["shown_frames"], gi
if gi["shown_frames"] > gi["wrong_identities"]:
    assert gi["tip_error_median_mm"] <= 1.5, gi
# --method both: the paper's method on the same session (issue 38 item 1, docs/paper_method.md).
pm = out["paper_method"]["stages"]
assert sorted(pm) == ["depth", "guidance", "reconstruction", "registration", "tracking"], sorted(pm)
for name, stage in pm.items():
    assert stage["ok"], (name, stage["error"])
    for key, value in stage.items():  # its artefacts lie under paper_method/
        if isinstance(value, str) and key.endswith(("_ply", "_csv", "_json")):
            assert os.path.isfile(os.path.join(d, "paper_method", value)), (name, key, value)
m = pm["depth"]["model"]
assert m["C4_mm"] == 0.0 and m["cyclic_error"]["amplitude_mm"] == 0.0, m  # Eq. 3 alone
assert not m["multipath_removed"] and m["tool_marker_observations_left_out"] == 0, m
# The hand placement: 5 mm at the skin's centroid and 5 deg about it; the targets lie within
# ~60 mm of it, so the start is 5 +- 5.3 mm off there (sin 5 deg x 60 mm).
assert 0.0 < pm["registration"]["start_tre_mm"] <= 10.3, pm["registration"]
assert pm["registration"]["accepted"], pm["registration"]  # the paper refuses nothing
print(f"demo ok in {out['elapsed_s']:.1f} s: f_rf bias {s['marker_error']['bias_after_max_abs_mm']:.3f} mm, "
      f"head {head[0]['after_median_mm']:.3f} mm ({head[0]['reduction_percent']:.1f} %), "
      f"reconstruction {s['reconstruction']['median_mm']:.3f} mm, TRE {s['registration']['tre_mm']:.3f} mm, "
      f"entry {g['entry_median_mm']:.3f} mm, angle {g['angle_median_deg']:.3f} deg")
PY
