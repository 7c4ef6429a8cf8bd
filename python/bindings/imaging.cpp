// SPDX-License-Identifier: BSD-3-Clause
// Volume (CtVolume, values as a (k, j, i) array) and skin extraction.
#include <pybind11/stl.h>

#include "convert.hpp"
#include "defines.hpp"
#include "tofnav/imaging/ct_volume.hpp"
#include "tofnav/imaging/skin.hpp"

namespace tofnav::python {
namespace {

CtVolume MakeVolume(const ArrayF& values, const ArrayD& image_from_ijk,
                    const std::string& modality) {
  if (values.ndim() != 3) throw py::value_error("values must be a (nz, ny, nx) array");
  if (image_from_ijk.ndim() != 2 || image_from_ijk.shape(0) != 4 || image_from_ijk.shape(1) != 4) {
    throw py::value_error("image_from_ijk must be a 4 x 4 array");
  }
  CtVolume volume;
  volume.dims = {static_cast<int>(values.shape(2)), static_cast<int>(values.shape(1)),
                 static_cast<int>(values.shape(0))};
  volume.values.assign(values.data(), values.data() + values.size());
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) volume.image_from_ijk(r, c) = image_from_ijk.at(r, c);
  }
  volume.modality = modality;
  volume.Check();
  return volume;
}

py::array_t<float> ValuesArray(const CtVolume& volume) {
  py::array_t<float> values({volume.nz(), volume.ny(), volume.nx()});
  std::copy(volume.values.begin(), volume.values.end(), values.mutable_data());
  return values;
}

}  // namespace

void DefineImaging(py::module_& m) {
  py::class_<CtVolume>(m, "Volume", "CT/MR volume; voxel (i, j, k) is values[k, j, i]")
      .def(py::init(&MakeVolume), py::arg("values"), py::arg("image_from_ijk"),
           py::arg("modality") = "")
      .def_property_readonly("values", &ValuesArray, "(nz, ny, nx) float32, HU for CT")
      .def_property_readonly(
          "image_from_ijk", [](const CtVolume& v) { return ArrayFromMatrix(v.image_from_ijk); },
          "4 x 4: voxel index (i, j, k, 1) -> LPS [mm]")
      .def_property_readonly("spacing_mm",
                             [](const CtVolume& v) { return ArrayFromVector(v.spacing_mm()); })
      .def_readonly("modality", &CtVolume::modality)
      .def_readonly("name", &CtVolume::name)
      .def_readonly("geometry_source", &CtVolume::geometry_source);

  py::class_<SkinResult>(m, "SkinResult")
      .def_readonly("mesh", &SkinResult::mesh)
      .def_readonly("threshold", &SkinResult::threshold)
      .def_readonly("threshold_source", &SkinResult::threshold_source)
      .def_readonly("mask_components", &SkinResult::mask_components)
      .def_readonly("kept_voxels", &SkinResult::kept_voxels)
      .def_readonly("filled_voxels", &SkinResult::filled_voxels)
      .def_readonly("dropped_triangles", &SkinResult::dropped_triangles);
  m.def(
      "extract_skin",
      [](const CtVolume& volume, std::optional<double> threshold, bool keep_largest_component,
         bool fill_cavities, double opening_radius_mm, int smoothing_iterations,
         double decimation_cell_mm) {
        py::gil_scoped_release release;
        return ExtractSkin(volume, {.threshold = threshold,
                                    .keep_largest_component = keep_largest_component,
                                    .fill_cavities = fill_cavities,
                                    .opening_radius_mm = opening_radius_mm,
                                    .smoothing_iterations = smoothing_iterations,
                                    .decimation_cell_mm = decimation_cell_mm});
      },
      py::arg("volume"), py::arg("threshold") = py::none(),
      py::arg("keep_largest_component") = true, py::arg("fill_cavities") = true,
      py::arg("opening_radius_mm") = kDefaultOpeningRadiusMm, py::arg("smoothing_iterations") = 0,
      py::arg("decimation_cell_mm") = 0.0,
      "outer skin surface in image (LPS mm); threshold default: -300 HU for CT, Otsu otherwise");
}

}  // namespace tofnav::python
