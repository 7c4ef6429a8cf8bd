# SPDX-License-Identifier: BSD-3-Clause
"""Mesh and tool files: write, read back, compare; malformed files raise OSError."""
import numpy as np
import pytest

import tofnav

PLY_TOL_MM = 1e-4  # binary PLY stores float32 (a 100 mm coordinate keeps ~1e-5 mm)


def tetrahedron():
    vertices = np.array([[0.0, 0, 0], [100, 0, 0], [0, 100, 0], [0, 0, 100]]) + 0.123456789
    triangles = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    return tofnav.Mesh(vertices, triangles)


@pytest.mark.parametrize("name", ["m.ply", "m.obj", "m.stl"])
def test_mesh_round_trip(tmp_path, name):
    mesh = tetrahedron()
    tofnav.write_mesh(tmp_path / name, mesh)
    back = tofnav.read_mesh(tmp_path / name)
    # STL has no vertex indices (equal positions are merged on read): compare triangle corners.
    corners = back.vertices[back.triangles]
    np.testing.assert_allclose(corners, mesh.vertices[mesh.triangles], atol=PLY_TOL_MM)


def test_mesh_with_normals_and_scalars(tmp_path):
    mesh = tetrahedron()
    normals = mesh.compute_normals()
    scalars = np.array([0.5, 1.5, 2.5, 3.5], dtype=np.float32)
    full = tofnav.Mesh(mesh.vertices, mesh.triangles, normals=normals, scalars=scalars)
    tofnav.write_mesh(tmp_path / "full.ply", full)
    back = tofnav.read_mesh(tmp_path / "full.ply")
    np.testing.assert_allclose(back.normals, normals, atol=1e-6)  # float32 in the file
    np.testing.assert_array_equal(back.scalars, scalars)
    with pytest.raises(ValueError):
        tofnav.Mesh(mesh.vertices, np.array([[0, 1, 7]]))  # index out of range


def test_tool_round_trip(tmp_path):
    markers = np.array([[0.0, 0, 0], [50, 0, 0], [0, 70, 0], [30, 40, 15]])
    tool = tofnav.Tool("HeadRef", markers, marker_type="disc", marker_diameter_mm=10.0,
                       tip=[1.0, 2.0, 3.0])
    tofnav.write_tool(tmp_path / "tool.json", tool)
    back = tofnav.read_tool(tmp_path / "tool.json")
    assert back.name == "HeadRef" and back.marker_type == "disc"
    assert back.marker_diameter_mm == 10.0
    np.testing.assert_array_equal(back.markers, markers)
    np.testing.assert_array_equal(back.tip, [1.0, 2.0, 3.0])


def test_malformed_files_raise_os_error_naming_the_file(tmp_path):
    (tmp_path / "t.ply").write_bytes(b"ply\nformat binary_little_endian 1.0\nelement vertex 9\n")
    with pytest.raises(OSError, match="t.ply"):
        tofnav.read_mesh(tmp_path / "t.ply")
    (tmp_path / "tool.json").write_text('{"name": "x", "markers": [[0, 0')
    with pytest.raises(OSError, match="tool.json"):
        tofnav.read_tool(tmp_path / "tool.json")
    with pytest.raises(OSError):
        tofnav.read_volume(tmp_path / "missing.nrrd")
    with pytest.raises(OSError):
        tofnav.read_hl2ss_calibration(tmp_path)
