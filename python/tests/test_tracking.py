# SPDX-License-Identifier: BSD-3-Clause
"""Markers and ToolTracker on the simulated board: poses against the simulator's truth."""
import numpy as np
import pytest

import tofnav
from conftest import rotation_error_rad

TRACK_TOL_MM = 1.0  # ideal sensor; marker centroids and 1 mm range codes limit the pose
TRACK_TOL_RAD = 0.01


def tool_from_truth(truth, name):
    markers = truth["tools"][name]["markers"]
    return tofnav.Tool(name, np.array([m["centre_in_tool"] for m in markers]),
                       marker_type=markers[0]["shape"],
                       marker_diameter_mm=markers[0]["diameter_mm"])


def test_tool_tracker_recovers_the_true_pose(simulated):
    out, _, truth = simulated
    recording = tofnav.open_recording(out / "rm_depth_ahat.bin")
    camera = tofnav.AhatCamera(tofnav.read_hl2ss_calibration(out / "calibration"))
    tool = tool_from_truth(truth, "ref")
    tracker = tofnav.ToolTracker([tool])
    assert tracker.tools[0].name == "ref"
    for i in range(recording.frame_count):
        frame = recording.read_frame(i)
        markers = tofnav.locate_markers(frame, camera)
        assert len(markers) == 6
        # nothing in front of the board and its markers far apart: no damage flag (docs/tracking.md 6)
        assert not any(m.occluded or m.near_blob for m in markers)
        (tracked,) = tracker.track(markers, frame.timestamp_s)
        assert tracked.status == "ok"
        assert tracked.visible_markers == 6
        assert tracked.used_markers == 6
        # the fit's own per-axis sds under its noise model: known, and within the pose tolerances
        assert 0.0 < tracked.position_sd_mm < TRACK_TOL_MM
        assert 0.0 < tracked.rotation_sd_rad < TRACK_TOL_RAD
        pose = tracked.ahat_from_tool
        true_pose = np.array(truth["frames"][i]["ahat_from_ref"])
        assert np.linalg.norm(pose[:3, 3] - true_pose[:3, 3]) < TRACK_TOL_MM
        assert rotation_error_rad(pose, true_pose) < TRACK_TOL_RAD


def test_no_markers_means_no_pose(simulated):
    _, _, truth = simulated
    tracker = tofnav.ToolTracker([tool_from_truth(truth, "ref")])
    (tracked,) = tracker.track([], 0.0)
    assert tracked.status == "too_few_markers"
    assert tracked.ahat_from_tool is None


def test_bad_tool_raises_value_error():
    with pytest.raises(ValueError):
        tofnav.Tool("flat", np.zeros((3, 3)))  # coincident markers
