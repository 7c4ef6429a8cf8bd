# SPDX-License-Identifier: BSD-3-Clause
"""reconstruct: the simulated board fused in the reference tool's frame lies on the board."""
import numpy as np

import tofnav
from test_tracking import tool_from_truth

# The board is the plane z = 0 in world and the tool sits at z = +1 mm, unrotated: z = -1 in tool.
BOARD_Z_IN_TOOL_MM = -1.0
# Ideal sensor, 1 mm range codes (+-0.5 mm) of three identical static frames, 2 mm voxels (fast;
# measured median 0.19, p95 0.49 mm).
VOXEL_MM = 2.0
MEDIAN_TOL_MM = 0.3
P95_TOL_MM = 0.6


def test_reconstruct_recording_gives_the_board(simulated):
    out, _, truth = simulated
    recording = tofnav.open_recording(out / "rm_depth_ahat.bin")
    camera = tofnav.AhatCamera(tofnav.read_hl2ss_calibration(out / "calibration"))
    result = tofnav.reconstruct(recording, camera, tool_from_truth(truth, "ref"),
                                depth_model=tofnav.DepthErrorModel(),  # zero: Eq. 4 = identity
                                voxel_size_mm=VOXEL_MM,
                                head_region=False)  # a board, not a head
    assert result["frames_considered"] == 3 and result["frames_fused"] == 3
    assert result["roi_automatic"]
    z_error = np.abs(result["mesh"].vertices[:, 2] - BOARD_Z_IN_TOOL_MM)
    assert result["mesh"].triangles.shape[0] > 1000
    assert np.median(z_error) < MEDIAN_TOL_MM
    assert np.percentile(z_error, 95) < P95_TOL_MM
