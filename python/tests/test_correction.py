# SPDX-License-Identifier: BSD-3-Clause
"""Correction: Eq. (3)/(4) element-wise, a whole frame with a known linear bias, normals,
segmentation, and the f_rf fit of Eq. (1)/(2)."""
import numpy as np
import pytest

import tofnav

TRUE_MODEL = dict(c1_mm=3.0, c2=0.01, c3_mm=4.0)  # a linear bias of 7-11 mm on the plane
PLANE_RANGE_MM = 450.0
PLANE_TILT_RAD = 0.4
MARKER_UV = (300, 260)  # a bright 9 x 9 px "marker" measured without bias
AB_SURFACE, AB_MARKER = 200, 5000
# Ranges are rounded to 1 mm codes before correction (+-0.5 mm); normals come from those codes.
MEAN_TOL_MM = 0.05  # the rounding averages out over ~10^4 pixels
MAX_TOL_MM = 1.0  # 0.5 mm rounding + C3 x the theta error of normals of rounded ranges
INCIDENCE_TOL_RAD = 1e-3  # normals of the exact float32 range of a plane (measured 7e-5)
EXACT_MM = 1e-9  # double arithmetic


def tilted_plane(camera):
    """(true range (H, W), incidence (H, W)) of a plane through (0, 0, 450) tilted about y."""
    rays = camera.points_from_range(np.ones((camera.height, camera.width)))
    n = np.array([np.sin(PLANE_TILT_RAD), 0.0, -np.cos(PLANE_TILT_RAD)])  # faces the camera
    cos_n = rays @ n
    with np.errstate(invalid="ignore", divide="ignore"):
        d = (n @ np.array([0.0, 0.0, PLANE_RANGE_MM])) / cos_n
    valid = (cos_n < -0.2) & np.isfinite(d)
    v, u = np.mgrid[0:camera.height, 0:camera.width]
    valid &= (np.abs(u - 256) < 90) & (np.abs(v - 256) < 90)  # a 180 px window
    return np.where(valid, d, 0.0), np.where(valid, np.arccos(np.clip(-cos_n, 0, 1)), np.nan)


def biased_frame(camera, model):
    truth, theta = tilted_plane(camera)
    v, u = np.mgrid[0:camera.height, 0:camera.width]
    marker = (np.abs(u - MARKER_UV[0]) <= 4) & (np.abs(v - MARKER_UV[1]) <= 4)
    measured = np.where(marker, truth, truth + model.bias_mm(truth, np.nan_to_num(theta)))
    measured = np.where(truth > 0, np.rint(measured), 0).astype(np.uint16)
    ab = np.where(marker, AB_MARKER, AB_SURFACE).astype(np.uint16)
    return tofnav.Frame(measured, ab), truth, theta, marker


def test_model_inverts_its_bias():
    model = tofnav.DepthErrorModel(**TRUE_MODEL)
    d = np.linspace(200.0, 900.0, 8)
    theta = np.linspace(0.0, 1.2, 8)
    measured = d + model.bias_mm(d, theta)
    assert np.allclose(model.bias_mm(d, theta), 3.0 + 0.01 * d + 4.0 * theta, atol=EXACT_MM)
    assert np.allclose(model.correct_range_mm(measured, theta), d, atol=EXACT_MM)
    assert model.name == "linear-theta" and model.parameters == [3.0, 0.01, 4.0]
    with pytest.raises(ValueError):
        tofnav.DepthErrorModel(c2=-1.0)  # 1 + C2 must stay > 0


def whole_frame():
    """Head region off: every pixel with a range is surface."""
    return tofnav.HeadRegionOptions(enabled=False)


def test_correct_range_image_recovers_the_true_range(camera):
    model = tofnav.DepthErrorModel(**TRUE_MODEL)
    frame, truth, _, marker = biased_frame(camera, model)
    # A tilted plane is not a head: the automatic head region (which drops large planes) is off.
    options = tofnav.CorrectRangeOptions(
        segmentation=tofnav.SegmentationOptions(head_region=whole_frame()))
    result = tofnav.correct_frame(frame, camera, model, options)
    corrected = result["range_mm"]
    assert np.array_equal(corrected, tofnav.correct_range_image(frame, camera, model, options))
    labels = result["labels"]
    assert np.all(corrected[labels == tofnav.PIXEL_TRANSITION] == 0)
    head = (labels == tofnav.PIXEL_HEAD) & (corrected > 0)
    assert head.sum() > 10000
    error = corrected[head] - truth[head]
    assert abs(error.mean()) < MEAN_TOL_MM
    assert np.abs(error).max() < MAX_TOL_MM
    # Before correction the head is 7-11 mm too far: the test can fail.
    assert (frame.depth[head] - truth[head]).mean() > 5.0
    # Marker pixels: Eq. (2) with an empty f_rf keeps the (unbiased) measurement.
    on_marker = (labels == tofnav.PIXEL_MARKER) & (corrected > 0)
    assert on_marker.sum() == 81 and np.all(on_marker == marker)
    assert np.abs(corrected[on_marker] - truth[on_marker]).max() <= 0.5 + 1e-3


def test_segmentation_finds_marker_transition_and_head(camera):
    frame, _, _, _ = biased_frame(camera, tofnav.DepthErrorModel(**TRUE_MODEL))
    seg = tofnav.segment_frame(frame, camera, tofnav.SegmentationOptions(roi_radius_mm=60.0,
                                                                        head_region=whole_frame()))
    assert len(seg["markers"]) == 1 and seg["markers"][0]["pixels"].shape == (81, 2)
    u, v = MARKER_UV
    labels = seg["labels"]
    assert labels[v, u] == tofnav.PIXEL_MARKER
    assert labels[v, u + 7] == tofnav.PIXEL_TRANSITION  # 4 px half-width + 3 px dilation
    assert labels[v, u + 8] == tofnav.PIXEL_HEAD
    assert labels[v, 190] == tofnav.PIXEL_OUTSIDE  # beyond the 60 mm ROI
    with pytest.raises(AttributeError):
        tofnav.SegmentationOptions(no_such_option=1)


def test_range_normals_give_the_plane_incidence(camera):
    truth, theta = tilted_plane(camera)
    normals, incidence = tofnav.range_normals(truth.astype(np.float32), camera)
    v, u = np.mgrid[0:camera.height, 0:camera.width]
    interior = (np.abs(u - 256) < 80) & (np.abs(v - 256) < 80)  # away from the window's edge
    assert np.abs(incidence[interior] - theta[interior]).max() < INCIDENCE_TOL_RAD
    n = np.array([np.sin(PLANE_TILT_RAD), 0.0, -np.cos(PLANE_TILT_RAD)])
    assert np.abs(normals[interior] @ n - 1.0).max() < INCIDENCE_TOL_RAD
    assert np.all(normals[truth == 0] == 0)


def test_marker_range_fit_recovers_a_linear_f_rf(tmp_path):
    fit_tol_mm = 1e-6  # any csaps p fits a line exactly
    d = np.linspace(250.0, 750.0, 41)
    f_true = 1.5 + 0.006 * (d - 400.0)
    model, fit = tofnav.fit_marker_range_model(d, f_true)
    assert fit["site_count"] == 41 and fit["rms_residual_mm"] < fit_tol_mm
    grid = np.linspace(200.0, 800.0, 13)  # beyond the knots too (linear extension)
    assert np.abs(model.bias_mm(grid) - (1.5 + 0.006 * (grid - 400.0))).max() < fit_tol_mm
    assert np.abs(model.correct_range_mm(grid) - (grid - model.bias_mm(grid))).max() < EXACT_MM
    points = np.array([[10.0, -20.0, 500.0], [0.0, 0.0, 300.0]])
    moved = model.correct_points(points)
    r = np.linalg.norm(points, axis=1)
    assert np.allclose(np.linalg.norm(moved, axis=1), r - model.bias_mm(r), atol=EXACT_MM)
    assert np.allclose(np.cross(moved, points), 0.0, atol=1e-6)  # along the ray
    assert tofnav.MarkerRangeModel().empty and tofnav.MarkerRangeModel().bias_mm(500.0) == 0.0
    # Files: f_rf JSON and depth_model.json round trips.
    tofnav.write_marker_range(tmp_path / "frf.json", model)
    back = tofnav.read_marker_range(tmp_path / "frf.json")
    assert np.abs(back.bias_mm(grid) - model.bias_mm(grid)).max() < fit_tol_mm
    tofnav.write_depth_model(tmp_path / "dm.json", tofnav.DepthErrorModel(**TRUE_MODEL), model)
    depth_model, marker_range = tofnav.read_depth_model(tmp_path / "dm.json")
    assert depth_model.parameters == pytest.approx([3.0, 0.01, 4.0], abs=1e-12)
    assert marker_range is not None and not marker_range.empty
    with pytest.raises(OSError, match="dm.json"):
        (tmp_path / "dm.json").write_text('{"format": "tofnav-depth-model"')
        tofnav.read_depth_model(tmp_path / "dm.json")


def plane_range(camera, normal, point):
    """Range (H, W) of the plane through `point` with unit `normal`, 0 where it faces away."""
    rays = camera.points_from_range(np.ones((camera.height, camera.width)))
    cos_n = rays @ normal
    with np.errstate(invalid="ignore", divide="ignore"):
        d = (normal @ point) / cos_n
    return np.where((cos_n < -0.2) & np.isfinite(d) & (d > 0), d, 0.0)


def lambertian_ab(camera, range_mm, normal, albedo=0.8, ab_scale=65.0):
    """AB = K rho cos(theta) cos^2(off-axis) / d^2 (d in m), the model RemoveMultipath assumes."""
    rays = camera.points_from_range(np.ones((camera.height, camera.width)))
    cos_theta = np.clip(-(rays @ normal), 0.0, 1.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        ab = ab_scale * albedo * cos_theta * rays[..., 2] ** 2 / (range_mm * 1e-3) ** 2
    return np.where(range_mm > 0, np.clip(ab, 0, 65535), 0).astype(np.uint16)


def test_remove_multipath_leaves_a_plane_and_shortens_a_concave_corner(camera):
    # A plane cannot light itself: nothing to remove (float arithmetic only).
    plane_n = np.array([0.0, 0.0, -1.0])
    plane = plane_range(camera, plane_n, np.array([0.0, 0.0, 450.0])).astype(np.float32)
    corrected, stats = tofnav.remove_multipath(plane, lambertian_ab(camera, plane, plane_n), camera)
    assert stats["pixels_corrected"] > 100000 and stats["pixels_dropped"] == 0
    assert np.abs(corrected - plane)[plane > 0].max() < 1e-3
    # Two walls at 45 deg forming a crease at z = 500 mm, open towards the camera: each lights the
    # other, so both read long and the correction shortens both, mirror-symmetrically.
    s = np.sqrt(0.5)
    left_n, right_n = np.array([s, 0.0, -s]), np.array([-s, 0.0, -s])
    crease = np.array([0.0, 0.0, 500.0])
    left, right = plane_range(camera, left_n, crease), plane_range(camera, right_n, crease)
    v, u = np.mgrid[0:camera.height, 0:camera.width]
    x = camera.points_from_range(np.ones((camera.height, camera.width)))[..., 0]
    use_left = (x < 0) & (left > 0)
    corner = np.where(use_left, left, np.where(x >= 0, right, 0.0))
    corner = np.where((np.abs(v - 256) < 120) & (corner < 700), corner, 0.0).astype(np.float32)
    ab = np.where(use_left, lambertian_ab(camera, corner, left_n),
                  lambertian_ab(camera, corner, right_n)).astype(np.uint16)
    corrected, stats = tofnav.remove_multipath(corner, ab, camera)
    shift = np.where(corrected > 0, corner - corrected, np.nan)
    centre_u = int(round(camera.principal_point_px[0]))
    left_shift = np.nanmean(shift[200:312, centre_u - 60:centre_u - 10])
    right_shift = np.nanmean(shift[200:312, centre_u + 10:centre_u + 60])
    assert left_shift > 1.0 and right_shift > 1.0  # mm-level in a concave corner
    assert abs(left_shift - right_shift) < 0.1 * left_shift  # the scene is mirror-symmetric
    off = tofnav.MultipathCorrectionOptions(enabled=False)
    same, _ = tofnav.remove_multipath(corner, ab, camera, off)
    assert np.array_equal(same, corner)
    with pytest.raises(ValueError):
        tofnav.remove_multipath(corner, ab, camera, tofnav.MultipathCorrectionOptions(passes=0))
    model = tofnav.DepthErrorModel()
    assert not model.multipath.enabled  # a model says whether it was identified with it
