# SPDX-License-Identifier: BSD-3-Clause
"""Surface and paired-point registration recover a known transform."""
import numpy as np

import tofnav
from conftest import rigid, rotation_error_rad

SURFACE_TOL_MM = 0.1  # exact correspondences on the same samples: ICP converges to the truth
SURFACE_TOL_RAD = 1e-3
PAIRED_TOL_MM = 1e-9  # noise-free pairs: the SVD solution is exact up to rounding


def bumpy_patch():
    """A 120 x 100 mm height field with three distinct bumps (no symmetry), 2 mm grid."""
    x, y = np.meshgrid(np.arange(-60.0, 60.1, 2.0), np.arange(-50.0, 50.1, 2.0))
    z = (12 * np.exp(-((x - 20) ** 2 + (y - 10) ** 2) / 300)
         + 8 * np.exp(-((x + 25) ** 2 + (y + 15) ** 2) / 200)
         + 0.004 * x * y + 0.003 * x**2)
    vertices = np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1)
    rows, cols = x.shape
    index = np.arange(rows * cols).reshape(rows, cols)
    a, b = index[:-1, :-1].ravel(), index[:-1, 1:].ravel()
    c, d = index[1:, :-1].ravel(), index[1:, 1:].ravel()
    triangles = np.concatenate([np.stack([a, b, d], 1), np.stack([a, d, c], 1)])
    return tofnav.Mesh(vertices, triangles)


def test_surface_registration_recovers_a_known_transform():
    skin_in_image = bumpy_patch()
    normals_in_image = skin_in_image.compute_normals()  # +z side is outside
    assert np.all(normals_in_image[:, 2] > 0)
    tool_from_image = rigid([0.1, -0.2, 0.3], [15.0, -8.0, 250.0])
    # The reconstruction: the central part of the skin, in tool.
    keep = np.all(np.abs(skin_in_image.vertices[:, :2]) < 40.0, axis=1)
    points = skin_in_image.vertices[keep] @ tool_from_image[:3, :3].T + tool_from_image[:3, 3]
    normals = normals_in_image[keep] @ tool_from_image[:3, :3].T
    guess = rigid([0.03, 0.02, -0.02], [2.0, -1.5, 1.0]) @ tool_from_image  # 2-3 deg, 3 mm off
    result = tofnav.register_surface(points, skin_in_image, normals=normals,
                                     targets_in_image=np.array([[0.0, 0.0, -60.0]]),
                                     tool_from_image_guess=guess)
    assert result.accepted, result.message
    assert result.status == "ok"
    estimate = result.tool_from_image
    assert np.linalg.norm(estimate[:3, 3] - tool_from_image[:3, 3]) < SURFACE_TOL_MM
    assert rotation_error_rad(estimate, tool_from_image) < SURFACE_TOL_RAD
    assert result.rmse_mm < SURFACE_TOL_MM
    assert result.inlier_fraction > 0.9
    assert len(result.predicted_tre_mm) == 1


def test_paired_points_recover_a_known_transform():
    rng = np.random.default_rng(3)
    source = rng.uniform(-50, 50, size=(6, 3))
    target_from_source = rigid([0.4, 0.1, -0.7], [10.0, 20.0, -30.0])
    target = source @ target_from_source[:3, :3].T + target_from_source[:3, 3]
    estimate, fre_rms_mm, residuals_mm = tofnav.register_paired_points(source, target)
    np.testing.assert_allclose(estimate, target_from_source, atol=PAIRED_TOL_MM)
    assert fre_rms_mm < PAIRED_TOL_MM and len(residuals_mm) == 6


def test_collinear_pairs_raise_value_error():
    line = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0]])
    try:
        tofnav.register_paired_points(line, line)
    except ValueError:
        return
    raise AssertionError("collinear points were accepted")
