# SPDX-License-Identifier: BSD-3-Clause
"""tofnav: HoloLens 2 AHAT time-of-flight surgical navigation (Li et al.), thin C++ bindings.

Units: mm, s, rad. Transforms are 4 x 4 numpy arrays named ``b_from_a`` (p_b = M @ p_a).
Errors: C++ precondition failures raise ValueError, file and format errors raise OSError, both
with the C++ message (file, byte offset and what was expected for readers). See docs/python.md.
"""
from ._tofnav import (  # noqa: F401
    AhatCamera,
    Calibration,
    Frame,
    Marker,
    Mesh,
    Recording,
    SkinResult,
    SurfaceRegistration,
    Tool,
    ToolTracker,
    TrackedTool,
    TsdfVolume,
    Volume,
    builtin_scenario_summary,
    builtin_scenarios,
    extract_skin,
    locate_markers,
    open_recording,
    read_hl2ss_calibration,
    read_mesh,
    read_tool,
    read_volume,
    register_paired_points,
    register_surface,
    simulate,
    synthetic_calibration,
    write_mesh,
    write_tool,
    write_volume,
)

__all__ = [name for name in dir() if not name.startswith("_")]
