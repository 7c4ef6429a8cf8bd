// SPDX-License-Identifier: BSD-3-Clause
// One Define<Module> per bindings file; module.cpp calls them in dependency order.
#pragma once

#include <pybind11/pybind11.h>

namespace tofnav::python {

void DefineCore(pybind11::module_& m);      // Mesh, rigid helpers
void DefineSensor(pybind11::module_& m);    // Calibration, Frame, AhatCamera
void DefineImaging(pybind11::module_& m);   // Volume, extract_skin
void DefineTracking(pybind11::module_& m);  // Tool, locate_markers, ToolTracker
void DefineFusion(pybind11::module_& m);    // TsdfVolume
void DefineRegistration(pybind11::module_& m);
void DefineIo(pybind11::module_& m);   // recordings, calibration folders, meshes, volumes, tools
void DefineSim(pybind11::module_& m);  // simulate, builtin_scenarios

}  // namespace tofnav::python
