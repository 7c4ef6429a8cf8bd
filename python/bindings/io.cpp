// SPDX-License-Identifier: BSD-3-Clause
// Readers and writers: recordings, hl2ss calibration folders, meshes, volumes, tool JSON.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <memory>

#include "convert.hpp"
#include "defines.hpp"
#include "tofnav/casefile/tool_json.hpp"
#include "tofnav/mesh/mesh_io.hpp"
#include "tofnav/recording/hl2ss_calibration.hpp"
#include "tofnav/recording/open_recording.hpp"
#include "tofnav/volume/volume_io.hpp"

namespace tofnav::python {
namespace {

using Path = std::filesystem::path;

std::size_t CheckedIndex(const AhatRecording& recording, std::int64_t index) {
  if (index < 0 || static_cast<std::size_t>(index) >= recording.frame_count()) {
    throw py::index_error("frame index out of range");
  }
  return static_cast<std::size_t>(index);
}

void DefineRecording(py::module_& m) {
  py::class_<AhatRecording, std::unique_ptr<AhatRecording>>(
      m, "Recording", "an AHAT recording, read frame by frame")
      .def_property_readonly("format", &AhatRecording::format)
      .def_property_readonly("frame_count", &AhatRecording::frame_count)
      .def("__len__", &AhatRecording::frame_count)
      .def(
          "timestamps_s",
          [](const AhatRecording& r) {
            py::array_t<double> times(static_cast<py::ssize_t>(r.frame_count()));
            for (std::size_t i = 0; i < r.frame_count(); ++i) {
              times.mutable_at(static_cast<py::ssize_t>(i)) =
                  static_cast<double>(r.host_ticks(i)) * kSecondsPerHostTick;
            }
            return times;
          },
          "host timestamps of every frame [s]")
      .def(
          "read_frame",
          [](const AhatRecording& r, std::int64_t index) {
            // The GIL stays held: one recording must not be read from two threads at once.
            return r.ReadFrame(CheckedIndex(r, index));
          },
          py::arg("index"))
      .def("calibration", &AhatRecording::calibration,
           "the calibration stored with the recording (StreamRecorder), else None");
  m.def("open_recording", &OpenAhatRecording, py::arg("path"),
        "hl2ss .bin file or StreamRecorder folder (OpenAhatRecording)");
}

}  // namespace

void DefineIo(py::module_& m) {
  DefineRecording(m);
  m.def("read_hl2ss_calibration", &ReadHl2ssCalibration, py::arg("path"),
        py::arg("sample_offset_px") = py::none(),
        "hl2ss calibration folder (<path>/rm_depth_ahat/ or that folder itself)");
  m.def(
      "read_mesh", [](const Path& path) { return ReadMesh(path); }, py::arg("path"),
      "PLY, STL or OBJ by extension");
  m.def(
      "write_mesh",
      [](const Path& path, const TriangleMesh& mesh, bool binary) {
        WriteMesh(path, mesh, {.binary = binary});
      },
      py::arg("path"), py::arg("mesh"), py::arg("binary") = true,
      "PLY, STL or OBJ by extension, atomically");
  m.def("read_volume", &ReadVolume, py::arg("path"),
        "DICOM folder, NRRD, NIfTI or .inv3 -> Volume in LPS");
  m.def(
      "write_volume", [](const Path& path, const CtVolume& volume) { WriteVolume(path, volume); },
      py::arg("path"), py::arg("volume"), ".nrrd, .nii or .nii.gz (float32)");
  m.def("read_tool", &ReadToolJson, py::arg("path"), "tool JSON -> Tool");
  m.def("write_tool", &WriteToolJson, py::arg("path"), py::arg("tool"), "Tool -> JSON, atomically");
}

}  // namespace tofnav::python
