// SPDX-License-Identifier: BSD-3-Clause
// One-call reconstruction of a recording (Sec. III-B) and the depth-model / f_rf files.
#include "tofnav/pipeline/reconstruct.hpp"

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <optional>

#include "convert.hpp"
#include "defines.hpp"
#include "tofnav/casefile/depth_model_json.hpp"
#include "tofnav/casefile/marker_range_json.hpp"
#include "tofnav/correction/correct_range.hpp"
#include "tofnav/pipeline/reconstruct_correction.hpp"

namespace tofnav::python {
namespace {

using Path = std::filesystem::path;

struct ReconstructArgs {
  std::optional<DepthErrorModel> depth_model;
  std::optional<MarkerRangeModel> marker_error;
  std::optional<CorrectRangeOptions> correct_options;
  py::object roi_min, roi_max;
};

py::dict Reconstruct(const AhatRecording& recording, const AhatCamera& camera,
                     const ToolGeometry& tool, const ReconstructArgs& args,
                     ReconstructOptions options) {
  options.tsdf.roi_in_tool = OptionalBoxFromObjects(args.roi_min, args.roi_max);
  if (args.marker_error) options.marker_error = *args.marker_error;
  if (args.depth_model) {  // as `tofnav reconstruct --depth-model`
    UseDepthModel({*args.depth_model, args.marker_error}, options,
                  args.correct_options.value_or(CorrectRangeOptions{}));
  }
  ReconstructResult r;
  {
    const py::gil_scoped_release release;
    r = ReconstructSurface(recording, camera, tool, options);
  }
  py::dict out;
  out["mesh"] = r.mesh;
  out["roi_min"] = ArrayFromVector(r.roi_in_tool.min());
  out["roi_max"] = ArrayFromVector(r.roi_in_tool.max());
  out["roi_automatic"] = r.roi_automatic;
  out["frames_considered"] = r.frames_considered;
  out["frames_fused"] = r.frames_fused;
  out["frames_skipped"] = r.frames_skipped;
  out["skipped_by_status"] = r.skipped_by_status;
  out["blocks"] = r.blocks;
  out["total_s"] = r.total_s;
  return out;
}

}  // namespace

void DefineReconstruct(py::module_& m) {
  m.def(
      "reconstruct",
      [](const AhatRecording& recording, const AhatCamera& camera, const ToolGeometry& tool,
         std::optional<DepthErrorModel> depth_model, std::optional<MarkerRangeModel> marker_error,
         std::optional<CorrectRangeOptions> correct_options, double voxel_size_mm,
         double truncation_vox, double min_range_mm, double max_range_mm, py::object roi_min,
         py::object roi_max, std::size_t first_frame, std::size_t frame_step,
         std::optional<std::size_t> max_frames, bool largest_component,
         bool accept_partially_occluded, double min_weight, bool head_region) {
        ReconstructOptions options;
        options.tsdf.voxel_size_mm = voxel_size_mm;
        options.tsdf.truncation_vox = truncation_vox;
        options.tsdf.min_range_mm = min_range_mm;
        options.tsdf.max_range_mm = max_range_mm;
        options.first_frame = first_frame;
        options.frame_step = frame_step;
        options.max_frames = max_frames;
        options.largest_component = largest_component;
        options.accept_partially_occluded = accept_partially_occluded;
        options.mesh.min_weight = min_weight;
        options.head_region.enabled = head_region;
        return Reconstruct(recording, camera, tool,
                           {std::move(depth_model), std::move(marker_error),
                            std::move(correct_options), std::move(roi_min), std::move(roi_max)},
                           options);
      },
      py::arg("recording"), py::arg("camera"), py::arg("tool"), py::arg("depth_model") = py::none(),
      py::arg("marker_error") = py::none(), py::arg("correct_options") = py::none(),
      py::arg("voxel_size_mm") = 1.0, py::arg("truncation_vox") = 4.0,
      py::arg("min_range_mm") = 100.0, py::arg("max_range_mm") = 1000.0,
      py::arg("roi_min") = py::none(), py::arg("roi_max") = py::none(), py::arg("first_frame") = 0,
      py::arg("frame_step") = 1, py::arg("max_frames") = py::none(),
      py::arg("largest_component") = true, py::arg("accept_partially_occluded") = true,
      py::arg("min_weight") = 0.0, py::arg("head_region") = true,
      "tool-referenced TSDF reconstruction of a recording (ReconstructSurface, as `tofnav "
      "reconstruct`): f_rf on the tool's markers, Eq. (4) on the surface when a depth model is "
      "given; head_region=False keeps every surface pixel (not a head); -> dict with mesh (in "
      "tool), roi_min/max, frame counts, blocks, total_s");
  m.def(
      "read_depth_model",
      [](const Path& path) {
        DepthModelFile file = ReadDepthModelJson(path);
        return py::make_tuple(file.model, file.marker_range);
      },
      py::arg("path"), "depth_model.json -> (DepthErrorModel, MarkerRangeModel or None)");
  m.def(
      "write_depth_model",
      [](const Path& path, const DepthErrorModel& model,
         std::optional<MarkerRangeModel> marker_range) {
        WriteDepthModelJson(path, {model, std::move(marker_range)});
      },
      py::arg("path"), py::arg("model"), py::arg("marker_range") = py::none(),
      "depth_model.json, atomically (with the model's fit report)");
  m.def(
      "read_marker_range", [](const Path& path) { return ReadMarkerRangeJson(path).model; },
      py::arg("path"), "f_rf JSON (`tofnav fit-marker-error`) -> MarkerRangeModel");
  m.def(
      "write_marker_range",
      [](const Path& path, const MarkerRangeModel& model) {
        WriteMarkerRangeJson(path, {.model = model});
      },
      py::arg("path"), py::arg("model"), "f_rf JSON, atomically (no fit facts)");
}

}  // namespace tofnav::python
