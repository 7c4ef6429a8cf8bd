# SPDX-License-Identifier: BSD-3-Clause
"""TsdfVolume: a synthetic plane fused from two poses is meshed on the plane."""
import numpy as np

import tofnav
from conftest import rigid

PLANE_TOL_MM = 0.1  # projective TSDF of an exact plane: interpolation error only
PLANE_Z_MM = 400.0


def plane_range(camera, z_mm):
    """Range along every pixel's ray to the plane z = z_mm in ahat (0 where the ray misses)."""
    v, u = np.mgrid[0:camera.height, 0:camera.width]
    rays = camera.rays(np.stack([u.ravel(), v.ravel()], axis=1).astype(float))
    with np.errstate(invalid="ignore", divide="ignore"):
        r = z_mm / rays[:, 2]
    r[~np.isfinite(r) | (rays[:, 2] <= 0.2)] = 0.0
    return r.reshape(camera.height, camera.width).astype(np.float32)


def test_fused_plane_mesh_lies_on_the_plane(camera):
    # ROI: a 60 mm square of the plane, in the tool frame = ahat of the first view.
    tsdf = tofnav.TsdfVolume(camera, voxel_size_mm=1.0, roi_min=[-30, -30, PLANE_Z_MM - 10],
                             roi_max=[30, 30, PLANE_Z_MM + 10])
    first = tsdf.integrate(plane_range(camera, PLANE_Z_MM), np.eye(4))
    assert first["integrated"] and first["pixels_used"] > 0
    # A second view 20 mm closer along z, rotated slightly about the optical axis: the same
    # plane is at z = PLANE_Z_MM - 20 in that camera.
    tool_from_ahat = rigid([0, 0, 0.05], [0, 0, 20.0])
    tsdf.integrate(plane_range(camera, PLANE_Z_MM - 20.0), tool_from_ahat)
    skipped = tsdf.integrate(plane_range(camera, PLANE_Z_MM), None)
    assert not skipped["integrated"]
    assert tsdf.frames_integrated == 2 and tsdf.frames_skipped == 1
    mesh = tsdf.extract_mesh()
    assert mesh.triangles.shape[0] > 1000
    assert np.max(np.abs(mesh.vertices[:, 2] - PLANE_Z_MM)) < PLANE_TOL_MM
    assert np.max(np.abs(mesh.vertices[:, :2])) <= 30.0 + 1.0  # within the ROI (one voxel)
