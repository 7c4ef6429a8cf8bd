# SPDX-License-Identifier: BSD-3-Clause
"""Skin of a synthetic volume, and the volume through a file."""
import numpy as np
import pytest

import tofnav

RADIUS_MM = 30.0
SPHERE_TOL_MM = 0.05  # HU linear in the radius: marching cubes errs by curvature only
SPACING_MM = (1.0, 1.25, 1.5)


def sphere_volume():
    """HU = -300 - 100 (r - 30 mm): the -300 HU skin threshold is the 30 mm sphere."""
    n = (80, 64, 54)  # (nx, ny, nz)
    image_from_ijk = np.diag([*SPACING_MM, 1.0])
    image_from_ijk[:3, 3] = [-(n[i] - 1) * SPACING_MM[i] / 2 for i in range(3)]
    k, j, i = np.mgrid[0:n[2], 0:n[1], 0:n[0]]
    ijk1 = np.stack([i, j, k, np.ones_like(i)], axis=-1).astype(float)
    xyz = ijk1 @ image_from_ijk.T
    r = np.linalg.norm(xyz[..., :3], axis=-1)
    return tofnav.Volume((-300.0 - 100.0 * (r - RADIUS_MM)).astype(np.float32), image_from_ijk,
                         modality="CT")


def test_skin_of_a_sphere_volume():
    volume = sphere_volume()
    assert volume.values.shape == (54, 64, 80)
    np.testing.assert_allclose(volume.spacing_mm, SPACING_MM)
    skin = tofnav.extract_skin(volume)
    assert skin.threshold == -300.0 and skin.threshold_source == "CT default"
    radii = np.linalg.norm(skin.mesh.vertices, axis=1)
    assert np.max(np.abs(radii - RADIUS_MM)) < SPHERE_TOL_MM
    # Outward normals: along the radius.
    normals = skin.mesh.normals if len(skin.mesh.normals) else skin.mesh.compute_normals()
    assert np.min(np.sum(normals * skin.mesh.vertices / radii[:, None], axis=1)) > 0.9
    assert skin.mesh.surface_area_mm2() == pytest.approx(4 * np.pi * RADIUS_MM**2, rel=0.01)


def test_volume_round_trip_through_nrrd(tmp_path):
    volume = sphere_volume()
    tofnav.write_volume(tmp_path / "v.nrrd", volume)
    back = tofnav.read_volume(tmp_path / "v.nrrd")
    np.testing.assert_array_equal(back.values, volume.values)  # float32, lossless
    np.testing.assert_allclose(back.image_from_ijk, volume.image_from_ijk, atol=1e-9)


def test_empty_mask_raises_value_error():
    with pytest.raises(ValueError):
        tofnav.extract_skin(tofnav.Volume(np.full((4, 4, 4), -1000.0), np.eye(4)), threshold=0.0)
