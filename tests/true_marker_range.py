#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
# Writes f_rf as the set-up phase would measure it for a simulated case: the simulator's retro
# curve plus its wiggle and its entrance-angle gain (truth.json), as a tofnav-marker-range-error file.
# Usage: true_marker_range.py CASE_DIR OUT_JSON
import json
import math
import sys


def main() -> int:
    if len(sys.argv) != 3:
        print("usage: true_marker_range.py CASE_DIR OUT_JSON", file=sys.stderr)
        return 2
    t = json.load(open(f"{sys.argv[1]}/truth.json"))
    s = t['render']['sensor']
    retro = next(m for m in t['materials'] if m['retro_reflective'])
    a = retro['retro_curve_amplitude_mm']
    # The sheeting's entrance-angle gain (docs/tracking.md 4), 0 in truth files that predate it.
    gain = retro.get('retro_angle_gain_mm_per_rad', 0.0)

    def wiggle(d):
        return s['wiggle_amplitude_mm'] * math.sin(
            2 * math.pi * d / s['wiggle_period_mm'] + s['wiggle_phase_rad'])

    xs, ys = [], []
    for d in [150.0 + 5.0 * i for i in range(171)]:
        observed = d + a * (d - 300.0) / 400.0
        total = observed + wiggle(observed) - d
        xs.append(d + total)
        ys.append(total)
    json.dump({"format": "tofnav-marker-range-error", "version": 1, "range_unit": "mm",
               "smoothing_p": 1.0, "knots_mm": xs, "bias_mm": ys,
               "second_derivative_per_mm": [0.0] * len(xs),
               "entrance_gain_mm_per_rad": gain}, open(sys.argv[2], 'w'))
    return 0


if __name__ == "__main__":
    sys.exit(main())
