// SPDX-License-Identifier: BSD-3-Clause
// Option structs built from Python keyword arguments:
// `tofnav.SegmentationOptions(roi_radius_mm=60)`.
#pragma once

#include <pybind11/pybind11.h>

namespace tofnav::python {

/// A default-constructed T with each keyword set through its bound attribute (unknown names raise
/// AttributeError, wrong types TypeError): the C++ defaults stay the only defaults.
template <typename T>
T OptionsFromKwargs(const pybind11::kwargs& kwargs) {
  T value{};
  const pybind11::object view = pybind11::cast(&value, pybind11::return_value_policy::reference);
  for (const auto& [key, item] : kwargs) pybind11::setattr(view, key, item);
  return value;
}

/// `py::class_<T>(...)` with the keyword constructor above.
template <typename T>
pybind11::class_<T> OptionsClass(pybind11::module_& m, const char* name, const char* doc) {
  pybind11::class_<T> options(m, name, doc);
  options.def(pybind11::init(&OptionsFromKwargs<T>));
  return options;
}

}  // namespace tofnav::python
