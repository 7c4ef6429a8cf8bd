# SPDX-License-Identifier: BSD-3-Clause
"""AhatCamera: rays, projection and range-to-points against each other and the definitions."""
import numpy as np
import pytest

RAY_ROUND_TRIP_TOL_PX = 1e-6  # Project() runs Newton on the bilinear table to below 1e-4 px steps
UNIT_TOL = 1e-6  # unit rays are float32 in the camera's table
RANGE_TOL_MM = 1e-3  # float32 rays times 500 mm


def test_rays_project_back_to_their_pixels(camera):
    rng = np.random.default_rng(7)
    pixels = rng.uniform(150.0, 350.0, size=(200, 2))
    rays = camera.rays(pixels)
    assert rays.shape == (200, 3)
    assert np.all(np.isfinite(rays))
    np.testing.assert_allclose(np.linalg.norm(rays, axis=1), 1.0, atol=UNIT_TOL)
    for range_mm in (150.0, 800.0):
        back = camera.project(rays * range_mm)
        assert np.max(np.abs(back - pixels)) < RAY_ROUND_TRIP_TOL_PX


def test_project_outside_the_field_is_nan(camera):
    behind = camera.project(np.array([[0.0, 0.0, -100.0]]))
    assert np.all(np.isnan(behind))


def test_points_from_range_lie_on_the_rays(camera):
    range_mm = np.full((camera.height, camera.width), 500.0)
    range_mm[0, 0] = 0.0
    points = camera.points_from_range(range_mm)
    assert points.shape == (camera.height, camera.width, 3)
    valid = camera.valid_mask()
    valid[0, 0] = False
    np.testing.assert_allclose(np.linalg.norm(points[valid], axis=1), 500.0, atol=RANGE_TOL_MM)
    assert np.all(points[~valid] == 0.0)
    v, u = 240, 300
    ray = camera.rays(np.array([[float(u), float(v)]]))[0]
    np.testing.assert_allclose(points[v, u], 500.0 * ray, atol=RANGE_TOL_MM)


def test_bad_shapes_raise_value_error(camera):
    with pytest.raises(ValueError):
        camera.rays(np.zeros((3, 3)))
    with pytest.raises(ValueError):
        camera.points_from_range(np.zeros((4, 4)))
