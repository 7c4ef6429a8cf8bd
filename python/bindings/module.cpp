// SPDX-License-Identifier: BSD-3-Clause
// The extension module `tofnav._tofnav`: exception translation and the per-module definitions.
#include <pybind11/pybind11.h>

#include "defines.hpp"
#include "tofnav/io/io_error.hpp"

PYBIND11_MODULE(_tofnav, m) {
  m.doc() = "tofnav: HoloLens 2 AHAT time-of-flight surgical navigation (thin C++ bindings)";
  // PreconditionError derives from std::invalid_argument: pybind11 raises ValueError for it.
  // IoError (a file that cannot be read or written, or malformed content) becomes OSError.
  pybind11::register_exception_translator([](std::exception_ptr error) {
    try {
      if (error) std::rethrow_exception(error);
    } catch (const tofnav::IoError& e) {
      PyErr_SetString(PyExc_OSError, e.what());
    }
  });
  tofnav::python::DefineCore(m);
  tofnav::python::DefineSensor(m);
  tofnav::python::DefineImaging(m);
  tofnav::python::DefineTracking(m);
  tofnav::python::DefineFusion(m);
  tofnav::python::DefineRegistration(m);
  tofnav::python::DefineIo(m);
  tofnav::python::DefineSim(m);
  tofnav::python::DefineCorrection(m);
  tofnav::python::DefineIdentification(m);
  tofnav::python::DefineNavigation(m);
  tofnav::python::DefineReconstruct(m);
}
