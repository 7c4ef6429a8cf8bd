# SPDX-License-Identifier: BSD-3-Clause
"""Identification (Eq. 6-7, smoothness only) on simulated sphere "heads" with stick-on markers:
the head is measured with a known linear bias, the markers without; the fit moves C to it."""
import numpy as np

import tofnav

TRUE_MODEL = dict(c1_mm=2.8, c2=0.010, c3_mm=4.0)
HEAD_RADIUS_MM = 90.0
STICKER_RADIUS_MM = 5.0  # 10 mm stickers
# Head centres [mm] in ahat: ranges 310-460 mm, markers seen at varied incidence.
CENTRES = [(0, 0, 420), (40, -20, 480), (-30, 30, 400), (10, 40, 520), (-45, -35, 450)]
# Sticker directions from the head centre towards the camera (-z), tilted by (x, y) [rad].
TILTS = [(-0.30, 0.45), (0.28, 0.47), (-0.10, 0.72), (0.16, 0.62)]
# Over 300-600 mm and 0-0.8 rad the fitted bias must be within this fraction of the true one
# (RMS): ranges are 1 mm codes (+-0.5 mm), and C1 and C2 d trade off over a 200 mm depth span
# (measured 0.027).
RELATIVE_BIAS_TOL = 0.05


def sticker_centres(centre):
    out = []
    for tx, ty in TILTS:
        direction = np.array([np.sin(tx), np.sin(ty), -np.cos(tx) * np.cos(ty)])
        out.append(centre + HEAD_RADIUS_MM * direction / np.linalg.norm(direction))
    return np.array(out)


def sphere_frame(rays, model, centre):
    """A frame of the sphere at `centre` seen along `rays` ((H, W, 3), zero where invalid)."""
    centre = np.asarray(centre, dtype=float)
    b = rays @ centre
    disc = b**2 - (centre @ centre - HEAD_RADIUS_MM**2)
    hit = (disc > 0) & (np.linalg.norm(rays, axis=2) > 0.5)
    d = np.where(hit, b - np.sqrt(np.maximum(disc, 0)), 0.0)
    points = rays * d[..., None]
    normal = (points - centre) / HEAD_RADIUS_MM
    theta = np.arccos(np.clip(-np.sum(normal * rays, axis=2), 0.0, 1.0))
    marker = np.zeros_like(hit)
    for sticker in sticker_centres(centre):  # only near the sticker: cheap on 512 x 512
        marker |= hit & (np.sum((points - sticker) ** 2, axis=2) < STICKER_RADIUS_MM**2)
    measured = np.where(marker, d, d + model.bias_mm(d, theta))
    depth = np.where(hit, np.rint(measured), 0).astype(np.uint16)
    ab = np.where(marker, 5000, np.where(hit, 400, 0)).astype(np.uint16)
    return tofnav.Frame(depth, ab)


def test_identification_moves_c_to_the_truth(camera):
    truth = tofnav.DepthErrorModel(**TRUE_MODEL)
    rays = camera.points_from_range(np.ones((camera.height, camera.width)))
    frames = [tofnav.prepare_identification_frame(sphere_frame(rays, truth, c), camera, index=i)
              for i, c in enumerate(CENTRES)]
    assert all(f.marker_patches == 4 for f in frames)
    start = tofnav.DepthErrorModel()
    fitted = tofnav.identify_depth_model(frames, start)
    d, theta = np.meshgrid(np.linspace(300, 600, 7), np.linspace(0, 0.8, 5))
    true_bias = truth.bias_mm(d, theta)
    rms = lambda e: float(np.sqrt(np.mean(e**2)))  # noqa: E731
    assert rms(fitted.bias_mm(d, theta) - true_bias) < RELATIVE_BIAS_TOL * rms(true_bias)
    assert abs(fitted.c3_mm - TRUE_MODEL["c3_mm"]) < abs(start.c3_mm - TRUE_MODEL["c3_mm"])
    report = fitted.report
    assert report["costs"] == "smoothness" and report["frames_used"] == len(CENTRES)
    assert report["final_cost"] < 0.1 * report["initial_cost"]
    # The cost of Eq. (7) agrees: lower at the fit than at the start.
    assert (tofnav.identification_cost(frames, fitted)["total"]
            < tofnav.identification_cost(frames, start)["total"])
