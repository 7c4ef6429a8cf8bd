// SPDX-License-Identifier: BSD-3-Clause
// TsdfVolume: integrate range images with a pose, extract the zero-level mesh.
#include <pybind11/stl.h>

#include "convert.hpp"
#include "defines.hpp"
#include "tofnav/fusion/marching_cubes.hpp"
#include "tofnav/fusion/tsdf_volume.hpp"

namespace tofnav::python {
namespace {

TsdfVolume MakeTsdf(const AhatCamera& camera, double voxel_size_mm, double truncation_vox,
                    double min_range_mm, double max_range_mm, const py::object& roi_min,
                    const py::object& roi_max) {
  TsdfOptions options{.voxel_size_mm = voxel_size_mm,
                      .truncation_vox = truncation_vox,
                      .min_range_mm = min_range_mm,
                      .max_range_mm = max_range_mm};
  options.roi_in_tool = OptionalBoxFromObjects(roi_min, roi_max);
  return TsdfVolume(options, camera);
}

py::dict Integrate(TsdfVolume& volume, const ArrayF& range_mm, const py::object& tool_from_ahat) {
  const Image<float> range = ImageFromArray<float>(range_mm, "range_mm");
  const std::optional<Rigid3d> pose = OptionalRigidFromObject(tool_from_ahat);
  // The GIL stays held (here and in extract_mesh): a volume is not safe to share between threads.
  const IntegrateResult result = volume.Integrate(range, pose);
  py::dict out;
  out["integrated"] = result.integrated;
  out["pixels_used"] = result.pixels_used;
  out["blocks_touched"] = result.blocks_touched;
  out["blocks_allocated"] = result.blocks_allocated;
  out["voxels_updated"] = result.voxels_updated;
  return out;
}

}  // namespace

void DefineFusion(py::module_& m) {
  py::class_<TsdfVolume>(m, "TsdfVolume", "projective TSDF in the tool frame (Sec. III-B)")
      .def(py::init(&MakeTsdf), py::arg("camera"), py::arg("voxel_size_mm") = 1.0,
           py::arg("truncation_vox") = 4.0, py::arg("min_range_mm") = 100.0,
           py::arg("max_range_mm") = 1000.0, py::arg("roi_min") = py::none(),
           py::arg("roi_max") = py::none(), py::keep_alive<1, 2>())
      .def("integrate", &Integrate, py::arg("range_mm"), py::arg("tool_from_ahat"),
           "fuse one (H, W) range image [mm, 0 = invalid] seen from tool_from_ahat (4 x 4, or "
           "None: the frame is skipped); returns the counts of IntegrateResult as a dict")
      .def(
          "extract_mesh",
          [](const TsdfVolume& volume, double min_weight) {
            return ExtractIsoSurface(volume, {.min_weight = min_weight});
          },
          py::arg("min_weight") = 0.0, "zero level set in tool [mm] (marching cubes)")
      .def_property_readonly("frames_integrated", &TsdfVolume::frames_integrated)
      .def_property_readonly("frames_skipped", &TsdfVolume::frames_skipped)
      .def_property_readonly("block_count", &TsdfVolume::block_count);
}

}  // namespace tofnav::python
