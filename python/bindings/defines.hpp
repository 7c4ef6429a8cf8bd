// SPDX-License-Identifier: BSD-3-Clause
// One Define<Module> per bindings file; module.cpp calls them in dependency order.
#pragma once

#include <pybind11/pybind11.h>

#include <vector>

namespace tofnav {
struct FrameResidual;
}  // namespace tofnav

namespace tofnav::python {

void DefineCore(pybind11::module_& m);      // Mesh, rigid helpers
void DefineSensor(pybind11::module_& m);    // Calibration, Frame, AhatCamera
void DefineImaging(pybind11::module_& m);   // Volume, extract_skin
void DefineTracking(pybind11::module_& m);  // Tool, locate_markers, ToolTracker
void DefineFusion(pybind11::module_& m);    // TsdfVolume
void DefineRegistration(pybind11::module_& m);
void DefineIo(pybind11::module_& m);   // recordings, calibration folders, meshes, volumes, tools
void DefineSim(pybind11::module_& m);  // simulate, builtin_scenarios
void DefineCorrection(pybind11::module_& m);      // f_rf, DepthErrorModel, normals, CorrectFrame
void DefineIdentification(pybind11::module_& m);  // IdentifyDepthModel over prepared frames
void DefineNavigation(pybind11::module_& m);      // Navigator, Guidance
void DefineReconstruct(pybind11::module_& m);     // reconstruct, depth model and f_rf files

/// Per-frame residuals of an identification as [{frame, err_c_mm, err_s_mm, markers}].
pybind11::list FrameResidualList(const std::vector<FrameResidual>& frames);

}  // namespace tofnav::python
