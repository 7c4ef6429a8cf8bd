#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# tofnav evaluate suite on the one-case smoke suite (spheres on posts, the drape removed, a
# perturbed device, multipath): one JSON object on stdout equal to suite.json, suite.html written, the row's
# figures present and within tolerances loose enough for the short run; bad suite files refused
# with the file and JSON path. Usage: suite_cli_test.sh TOFNAV
set -euo pipefail
tofnav=$1
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
"$tofnav" evaluate suite smoke --out "$scratch/suite" --json -q >"$scratch/stdout.json"
/usr/bin/python3 - "$scratch/stdout.json" "$scratch/suite" <<'PY'
import json, os, sys
out = json.load(open(sys.argv[1]))
d = sys.argv[2]
assert out == json.load(open(os.path.join(d, "suite.json"))), "stdout differs from suite.json"
assert out["format"] == "tofnav-suite-result" and len(out["rows"]) == 1
row = out["rows"][0]
assert row["ok"] or row["error"].startswith("registration: registration refused"), row["error"]
html = open(os.path.join(d, "suite.html")).read()
assert "phantom-spheres-bare-device" in html and "<script" not in html
# The case rendered through its own device: the session's calibration is the perturbed one.
case = os.path.join(d, "phantom-spheres-bare-device")
for f in ["uv2xy.bin", "extrinsics.bin"]:
    a = open(os.path.join(case, "device_1", "rm_depth_ahat", f), "rb").read()
    b = open(os.path.join(case, "session", "calibration", "rm_depth_ahat", f), "rb").read()
    assert a == b, f
# Sanity bounds for 60 session frames of a hard case (the suite's lines are in docs/suite.md
# and this case misses several today: issue 16). A wrong transform, frame or evaluation gives
# centimetres or nothing; these catch that, not the accuracy:
TRACKING_MM = 1.0        # sphere tools, filtered RMS (line 0.3 mm)
RECONSTRUCTION_MM = 5.0  # head median (line 0.4 mm)
ENTRY_MM = 20.0          # guidance entry median (line 1.2 mm; a refused registration of the
                         # operating-room session was measured at 105 mm)
for key, limit in [("tracking_mm", TRACKING_MM), ("reconstruction_mm", RECONSTRUCTION_MM),
                   ("entry_mm", ENTRY_MM)]:
    assert row[key] is not None and 0.0 < row[key] <= limit, (key, row[key])
assert any(l["figure"] == "reconstruction_mm" for l in row["acceptance"])
# The instrument as navigate shows it beside the headframe: its wrong frames, summed in the summary.
w = row["instrument_wrong_identities"]
assert w is None or w >= 0, w
assert out["summary"]["instrument_wrong_frames"] == (int(w) if w is not None else 0), out["summary"]
print("suite smoke:", {k: row[k] for k in ["tracking_mm", "reconstruction_mm", "entry_mm",
                                         "registration", "true_tre_mm", "wall_s"]})
PY
# The spread over seeds (issue 40): two runs of the case at seeds 5 + 100 + 0 and + 1, each in its
# own folder, the per-case median and worst, and the page's spread table. A short run: the rows'
# figures are checked above; here the bookkeeping.
"$tofnav" evaluate suite smoke --seeds 2 --seed-offset 100 --frames-scale 0.05 --stability 2 \
  --consensus --drop-truth-ranges \
  --out "$scratch/seeds" --json -q >"$scratch/seeds.json" || true
/usr/bin/python3 - "$scratch/seeds.json" "$scratch/seeds" <<'PY'
import json, os, sys
out = json.load(open(sys.argv[1]))
d = sys.argv[2]
assert out["seeds_per_case"] == 2 and out["seed_offset"] == 100, out.keys()
assert [r["seed"] for r in out["rows"]] == [105, 106], [r["seed"] for r in out["rows"]]
assert [r["name"] for r in out["rows"]] == ["phantom-spheres-bare-device@105",
                                           "phantom-spheres-bare-device@106"]
for seed in (105, 106):
    run = os.path.join(d, "phantom-spheres-bare-device", f"seed{seed}")
    assert os.path.isdir(run), seed
    # --drop-truth-ranges: the session's true range images are gone once the row is made, the
    # session's other files stay.
    assert not os.path.exists(os.path.join(run, "session", "truth_range_f32.bin")), run
    assert os.path.exists(os.path.join(run, "session", "truth.json")), run
s = out["spread"]["phantom-spheres-bare-device"]
assert s["cases"] == 2, s
values = [r["tracking_mm"] for r in out["rows"] if r.get("tracking_mm") is not None]
if values:
    assert abs(s["tracking_mm"]["worst"] - max(values)) < 1e-12, (s, values)
html = open(os.path.join(d, "suite.html")).read()
assert "Spread over seeds" in html
assert "Identification stability" in html and "consensus kept" in html
assert "mean head change" in html
# The tracking RMS's range over the seeds beside what its own sampling error would span
# (docs/statistics.md): both figures in the spread and on the page.
assert "expected from sampling" in html
if all(r["ok"] and r.get("tracking_mm_se") is not None for r in out["rows"]):
    assert all(r["tracking_mm_se"] > 0.0 for r in out["rows"]), [r["tracking_mm_se"] for r in out["rows"]]
    assert s["tracking_mm_sampling_range"] > 0.0, s
# Beside the orientation line, over the poses navigation shows settled (docs/navigation.md 1.2):
# a subset of the same frames, so present and positive wherever the line's figure is.
for r in out["rows"]:
    if r["ok"] and r.get("tracking_deg") is not None:
        assert r["tracking_deg_settled"] > 0.0, r
        assert "(settled %.3g)" % r["tracking_deg_settled"] in html, r["tracking_deg_settled"]
# --stability 2 --consensus: each row carries its depth stage's stability figures, and the spread
# their worst; the medoid of the three runs is kept, and its own stability is reported.
for r in out["rows"]:
    if r["ok"]:
        assert r["stability_c1_mm"] >= 0.0 and r["stability_head_mm"] >= 0.0, r
        assert r["consensus_kept_run"] in (0, 1, 2), r
        assert r["consensus_c1_mm"] >= 0.0 and r["consensus_head_mm"] >= 0.0, r
        # Without either subset the medoid of the two left is the full run (a tie): the change
        # is none when the full run was kept.
        if r["consensus_kept_run"] == 0:
            assert r["consensus_c1_mm"] == 0.0 and r["consensus_head_mm"] == 0.0, r
        # --consensus keeps the runs' mean by default (docs/correction.md 2.16), the very
        # coefficients its jackknife reports, and the mean's own stability is in the row.
        depth = r["stages"]["depth"]
        mean = depth["stability"]["consensus"]["mean"]
        assert depth["model"]["consensus"] == "mean" and mean["kept"] is True, depth["model"]
        assert depth["model"]["C1_mm"] == mean["C1_mm"], (depth["model"], mean)
        assert r["consensus_mean_c1_mm"] >= 0.0 and r["consensus_mean_head_mm"] >= 0.0, r
if all(r["ok"] for r in out["rows"]):
    assert s["stability_c1_mm"]["worst"] == max(r["stability_c1_mm"] for r in out["rows"]), s
print("suite --seeds 2:", {k: s[k] for k in ["cases", "cases_meeting_every_line"]})
PY
# --consensus needs runs to take the medoid of.
if "$tofnav" evaluate suite smoke --consensus --out "$scratch/bad" 2>"$scratch/err"; then
  echo "--consensus without --stability was accepted" >&2
  exit 1
fi
grep -q -- "--consensus needs --stability 2 or more" "$scratch/err"
if "$tofnav" evaluate suite smoke --stability 2 --consensus-medoid --out "$scratch/bad" \
  2>"$scratch/err"; then
  echo "--consensus-medoid without --consensus was accepted" >&2
  exit 1
fi
grep -q -- "--consensus-medoid needs --consensus (the runs to choose from)" "$scratch/err"
# --stages tracking: the marker stage, the session and the tracking only; the row's acceptance has
# the tracking lines alone. An unknown stage is refused with the known ones.
"$tofnav" evaluate suite smoke --stages tracking --frames-scale 0.05 --out "$scratch/stages" \
  --json -q >"$scratch/stages.json"
/usr/bin/python3 - "$scratch/stages.json" <<'PY'
import json, sys
row = json.load(open(sys.argv[1]))["rows"][0]
assert row["ok"], row["error"]
assert row["stages_run"] == ["marker_error", "session", "tracking"], row["stages_run"]
assert sorted(row["stages"]) == ["marker_error", "session", "tracking"], list(row["stages"])
assert [l["figure"] for l in row["acceptance"]] == ["tracking_mm", "tracking_deg"], row["acceptance"]
assert 0.0 < row["tracking_mm"] <= 1.0, row["tracking_mm"]  # TRACKING_MM above
PY
if "$tofnav" evaluate suite smoke --stages trackign --out "$scratch/bad" 2>"$scratch/err"; then
  echo "an unknown stage was accepted" >&2
  exit 1
fi
grep -q "^tofnav evaluate suite: --stages: unknown stage 'trackign' (stages: marker_error, " \
  "$scratch/err" || {
  cat "$scratch/err" >&2
  exit 1
}
# A bad suite file is refused with the file and the JSON path of the bad key.
refused_file() {  # refused_file NAME SUITE_JSON PATTERN
  printf '%s' "$2" >"$scratch/$1.json"
  if "$tofnav" evaluate suite "$scratch/$1.json" --out "$scratch/bad" 2>"$scratch/err"; then
    echo "$1.json was accepted" >&2
    exit 1
  fi
  grep -q "$1.json.*$3" "$scratch/err" || {
    cat "$scratch/err" >&2
    exit 1
  }
}
refused() {  # refused NAME CASE_JSON PATTERN
  refused_file "$1" "$(printf '{"format": "tofnav-suite", "cases": [%s]}' "$2")" "$3"
}
refused bad '{"name": "a", "tools": "wands"}' '\$.cases\[0\].tools: unknown value .wands.'
# The multipath quadrature of a case: a stride outside the simulator's range.
refused bad_stride '{"name": "a", "multipath_stride_px": 200}' \
  '\$.cases\[0\].multipath_stride_px: must lie in \[1, 128\] px'
# "stage": "per_device" (the default): the cases of one device share one whole stage (the
# built-in's 1800 frames), recorded once under stages/ and copied into each case's folder; a bad
# "stage" value is refused.
printf '{"format": "tofnav-suite", "name": "shared", "frames_scale": 0.05, "cases": [%s, %s]}' \
  '{"name": "a", "seed": 3}' '{"name": "b", "seed": 4}' >"$scratch/shared.json"
"$tofnav" evaluate suite "$scratch/shared.json" --stages marker_error --out "$scratch/shared" \
  --json -q >"$scratch/shared_out.json"
/usr/bin/python3 - "$scratch/shared_out.json" "$scratch/shared" <<'PY'
import json, os, sys
rows = json.load(open(sys.argv[1]))["rows"]
stages = [r["stages"]["marker_error"] for r in rows]
assert len(stages) == 2 and stages[0]["shared"] == stages[1]["shared"], stages
assert all(s["frames"] == 1800 for s in stages), [s["frames"] for s in stages]
assert os.listdir(os.path.join(sys.argv[2], "stages")) == [os.path.basename(stages[0]["shared"])]
frf = [open(os.path.join(sys.argv[2], c, "frf.json")).read() for c in ("a", "b")]
assert frf[0] == frf[1]
PY
refused_file bad_stage '{"format": "tofnav-suite", "stage": "per_run", "cases": [{"name": "a"}]}' \
  '\$.stage: expected "per_device" or "per_case"'
echo "suite_cli_test: ok"
