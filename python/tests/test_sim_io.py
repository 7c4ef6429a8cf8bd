# SPDX-License-Identifier: BSD-3-Clause
"""Simulator output read back through the readers, against the simulator's truth."""
import numpy as np
import pytest

import tofnav
from conftest import rotation_error_rad

DEPTH_QUANTISATION_TOL_MM = 0.5 + 1e-3  # RAW depth is the truth rounded to 1 mm codes
TIMESTAMP_TOL_S = 1e-7  # one host tick (100 ns)
RATE_HZ = 45.0  # scenario timing default
POSE_TOL_MM = 1e-3  # world_from_rig is float32 metres in the file
POSE_TOL_RAD = 1e-5
CALIBRATION_TOL_MM = 1e-3  # f32 extrinsics


def test_builtins_are_listed():
    names = tofnav.builtin_scenarios()
    assert "evd-usecase" in names and "marker-stage" in names
    assert tofnav.builtin_scenario_summary("evd-usecase")


def test_recording_depth_matches_truth_within_quantisation(simulated):
    out, summary, truth = simulated
    assert summary["frames"] == 3
    assert "truth_range_f32.bin" in summary["files"]
    recording = tofnav.open_recording(out / "rm_depth_ahat.bin")
    assert recording.frame_count == 3 and len(recording) == 3
    assert recording.format.startswith("hl2ss")
    assert recording.calibration() is None  # hl2ss keeps it in the calibration folder
    times = recording.timestamps_s()
    np.testing.assert_allclose(np.diff(times), 1.0 / RATE_HZ, atol=TIMESTAMP_TOL_S)
    truth_range = np.fromfile(out / "truth_range_f32.bin", dtype="<f4").reshape(-1, 512, 512)
    assert truth_range.shape[0] == 3
    for i in range(3):
        frame = recording.read_frame(i)
        assert frame.depth.shape == (512, 512) and frame.depth.dtype == np.uint16
        assert frame.ab.shape == (512, 512) and frame.ab.dtype == np.uint16
        assert frame.timestamp_s == pytest.approx(times[i], abs=TIMESTAMP_TOL_S)
        assert frame.timestamp_s == pytest.approx(truth["frames"][i]["timestamp"] * 1e-7,
                                                  abs=TIMESTAMP_TOL_S)
        depth = frame.depth.astype(float)
        hit = truth_range[i] > 0
        assert hit.sum() > 10000
        np.testing.assert_array_equal(depth > 0, hit)
        assert np.max(np.abs(depth[hit] - truth_range[i][hit])) <= DEPTH_QUANTISATION_TOL_MM
        world_from_rig = np.array(truth["frames"][i]["world_from_rig"])
        assert np.max(np.abs(frame.world_from_rig[:3, 3] - world_from_rig[:3, 3])) < POSE_TOL_MM
        assert rotation_error_rad(frame.world_from_rig, world_from_rig) < POSE_TOL_RAD
    with pytest.raises(IndexError):
        recording.read_frame(3)


def test_calibration_folder_matches_truth(simulated):
    out, _, truth = simulated
    calibration = tofnav.read_hl2ss_calibration(out / "calibration")
    assert calibration.uv2xy.shape == (512, 512, 2)
    rig_from_ahat = np.array(truth["rig_from_ahat"])
    assert np.max(np.abs(calibration.rig_from_ahat - rig_from_ahat)) < CALIBRATION_TOL_MM


def test_reader_errors_are_os_errors(tmp_path):
    bad = tmp_path / "bad.bin"
    bad.write_bytes(b"HL2SSV2")
    with pytest.raises(OSError, match="bad.bin"):
        tofnav.open_recording(bad)
    with pytest.raises(OSError):
        tofnav.simulate("no-such-scenario", tmp_path / "x")
