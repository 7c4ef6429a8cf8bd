#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# tofnav verify on the simulator's verify-landmarks scenario (issue 37 item 6): per seed, the true
# registration passes and every landmark's reported error is within 0.3 mm of the true
# registration error there (0); a registration perturbed by 3 mm fails, each reported error within
# 0.3 mm of the true one. Usage: verify_cli_test.sh TOFNAV TESTS_DIR [SEED...] (default: seed 1)
set -euo pipefail
tofnav=$1
tests=$2
shift 2
seeds=("$@")
[ ${#seeds[@]} -gt 0 ] || seeds=(1)
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
for seed in "${seeds[@]}"; do
  case_dir="$scratch/case$seed"
  "$tofnav" simulate verify-landmarks --seed "$seed" --out "$case_dir" -q >/dev/null
  /usr/bin/python3 "$tests/navigation_case_from_truth.py" "$case_dir" >/dev/null
  /usr/bin/python3 "$tests/true_marker_range.py" "$case_dir" "$scratch/frf.json"
  # The perturbed registration: the true one moved by 3 mm along a seeded direction and turned by
  # 0.5 deg about the image origin; the true error at each landmark follows from both.
  /usr/bin/python3 - "$case_dir" "$seed" <<'PY'
import json, math, random, sys
case, seed = sys.argv[1], int(sys.argv[2])
reg = json.load(open(f"{case}/tool_from_image.json"))
m = reg["target_from_source"]
rng = random.Random(seed)
d = [rng.gauss(0, 1) for _ in range(3)]
n = math.sqrt(sum(x * x for x in d))
shift = [3.0 * x / n for x in d]
a = math.radians(0.5)
turn = [[math.cos(a), -math.sin(a), 0], [math.sin(a), math.cos(a), 0], [0, 0, 1]]  # about image z
r = [[sum(m[i][k] * turn[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
t = [m[i][3] + shift[i] for i in range(3)]
perturbed = dict(reg)
perturbed["target_from_source"] = [r[0] + [t[0]], r[1] + [t[1]], r[2] + [t[2]], [0, 0, 0, 1]]
json.dump(perturbed, open(f"{case}/perturbed_from_image.json", "w"), indent=2)
PY
  for reg in tool_from_image perturbed_from_image; do
    status=0
    "$tofnav" verify "$case_dir/rm_depth_ahat.bin" --calibration "$case_dir/calibration" \
      --tool "$case_dir/tools/reference.json" --registration "$case_dir/$reg.json" \
      --pointer "$case_dir/tools/instrument.json" --landmarks "$case_dir/landmarks.mrk.json" \
      --marker-error "$scratch/frf.json" --no-igtl --json >"$scratch/$reg.json" || status=$?
    /usr/bin/python3 - "$case_dir" "$scratch/$reg.json" "$reg" "$status" "$seed" <<'PY'
import json, math, sys
case, out, reg, status, seed = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4]), sys.argv[5]
TOL_MM = 0.3  # issue 37: the reported error equals the true registration error within 0.3 mm
v = json.load(open(out))["verify"]
truth = json.load(open(f"{case}/truth.json"))
true_reg = json.load(open(f"{case}/tool_from_image.json"))["target_from_source"]
used = json.load(open(f"{case}/{reg}.json"))["target_from_source"]
def apply(m, p):
    return [sum(m[i][k] * p[k] for k in range(3)) + m[i][3] for i in range(3)]
landmarks = {l["name"]: l["in_image"] for l in truth["patient"]["landmarks"]}
assert v["touched"] == len(landmarks) == 4, v
worst = 0.0
for t in v["touches"]:
    p = landmarks[t["name"]]
    true_mm = math.dist(apply(used, p), apply(true_reg, p))
    diff = abs(t["error_mm"] - true_mm)
    worst = max(worst, diff)
    print(f"seed {seed} {reg}: {t['name']} reported {t['error_mm']:.3f} mm, true {true_mm:.3f} mm, "
          f"difference {diff:.3f} mm")
    assert diff <= TOL_MM, (t, true_mm)
expect_pass = reg == "tool_from_image"
assert v["passed"] == expect_pass and (status == 0) == expect_pass, (v["status"], status)
print(f"seed {seed} {reg}: {v['status']} (exit {status}); worst |reported - true| {worst:.3f} mm")
PY
  done
  [ "$seed" = "${seeds[0]}" ] || continue
  # The check as a step of navigate, as a user reads it: one line per touch, then the verdict.
  "$tofnav" navigate "$case_dir/rm_depth_ahat.bin" --calibration "$case_dir/calibration" \
    --tool "$case_dir/tools/reference.json" --registration "$case_dir/tool_from_image.json" \
    --plan "$case_dir/plan.mrk.json" --instrument "$case_dir/tools/instrument.json" \
    --verify "$case_dir/landmarks.mrk.json" --marker-error "$scratch/frf.json" --no-igtl \
    >"$scratch/navigate.txt"
  /usr/bin/python3 - "$scratch/navigate.txt" <<'PY'
import re, sys
lines = [l for l in open(sys.argv[1]).read().splitlines() if l.startswith("verify")]
names = ["nasion", "right_lateral_canthus", "left_lateral_canthus", "forehead"]
assert len(lines) == 5, lines
for name, line in zip(names, lines):
    assert re.fullmatch(rf"verify: {name} \d+\.\d\d mm ok \(rested \d\.\d\d s, \d+ frames\)", line), line
assert re.fullmatch(r"verify PASSED: largest error \d\.\d\d mm \(limit 2\.00 mm\)", lines[4]), lines[4]
print("navigate --verify:", lines[4])
PY
done
