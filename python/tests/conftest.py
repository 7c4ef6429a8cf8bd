# SPDX-License-Identifier: BSD-3-Clause
"""Shared fixtures: a synthetic camera and one short simulated recording (ideal sensor)."""
import json

import numpy as np
import pytest

import tofnav

# A board with a planar-six reference tool seen by a static headset at about 420 mm; the 'ideal'
# render preset switches every sensor effect off, so recorded depth = truth up to the 1 mm code.
SCENARIO = {
    "name": "python-board", "frames": 3,
    "objects": [{"name": "board", "shape": {"kind": "plane", "width_mm": 300, "height_mm": 300},
                 "material": "diffuse"}],
    "tools": [{"name": "ref", "preset": "planar-six", "pose": {"translation_mm": [0, 0, 1]}}],
    "camera": {"motion": {"kind": "static",
                          "pose": {"look_at": {"eye_mm": [60, 40, 420], "target_mm": [0, 0, 0]}}}},
    "render": {"preset": "ideal"},
}


@pytest.fixture(scope="session")
def camera():
    return tofnav.AhatCamera(tofnav.synthetic_calibration())


@pytest.fixture(scope="session")
def simulated(tmp_path_factory):
    """(folder, simulate() summary, truth.json) of a 3-frame run with truth depth."""
    out = tmp_path_factory.mktemp("sim")
    summary = tofnav.simulate(json.dumps(SCENARIO), out, truth_depth=True, json_text=True)
    with open(out / "truth.json", encoding="utf-8") as f:
        truth = json.load(f)
    return out, summary, truth


def rigid(rotation_vector, translation):
    """4 x 4 rigid transform from a rotation vector [rad] and a translation [mm] (Rodrigues)."""
    w = np.asarray(rotation_vector, dtype=float)
    angle = np.linalg.norm(w)
    k = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]]) / max(angle, 1e-300)
    m = np.eye(4)
    m[:3, :3] = np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k
    m[:3, 3] = translation
    return m


def rotation_error_rad(a, b):
    r = a[:3, :3].T @ b[:3, :3]
    return float(np.arccos(np.clip((np.trace(r) - 1) / 2, -1, 1)))
