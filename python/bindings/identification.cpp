// SPDX-License-Identifier: BSD-3-Clause
// Patient-specific identification of the depth model (Eq. 5-7) over prepared frames.
#include "tofnav/correction/identification.hpp"

#include <pybind11/stl.h>

#include <optional>
#include <vector>

#include "convert.hpp"
#include "defines.hpp"
#include "options.hpp"
#include "tofnav/correction/initial_pose.hpp"

namespace tofnav::python {
namespace {

using Frames = std::vector<IdentificationFrame>;
using Poses = std::vector<std::optional<Rigid3d>>;

/// Err_C's target: the CT skin indexed once, and image_from_ahat per frame (4 x 4 or None).
struct Target {
  std::optional<SurfaceIndex> skin;
  CorrectnessTarget target;
  const CorrectnessTarget* get() const { return skin ? &target : nullptr; }
};

void MakeTarget(Target& out, const Frames& frames, const std::optional<TriangleMesh>& skin,
                const std::optional<py::list>& image_from_ahat) {
  if (!skin) {
    if (image_from_ahat) throw py::value_error("image_from_ahat needs a skin");
    return;
  }
  if (!image_from_ahat || py::len(*image_from_ahat) != frames.size()) {
    throw py::value_error("with a skin, give image_from_ahat: one 4 x 4 (or None) per frame");
  }
  out.skin.emplace(*skin);
  out.target.skin_in_image = &*out.skin;
  for (const py::handle pose : *image_from_ahat) {
    out.target.image_from_ahat.push_back(
        OptionalRigidFromObject(py::reinterpret_borrow<py::object>(pose)));
  }
}

void DefineIdentificationOptions(py::module_& m) {
  OptionsClass<IdentificationSampling>(m, "IdentificationSampling",
                                       "PrepareIdentificationFrame options")
      .def_readwrite("segmentation", &IdentificationSampling::segmentation)
      .def_readwrite("normals", &IdentificationSampling::normals)
      .def_readwrite("patch_radius_mm", &IdentificationSampling::patch_radius_mm)
      .def_readwrite("min_patch_points", &IdentificationSampling::min_patch_points)
      .def_readwrite("max_patch_points", &IdentificationSampling::max_patch_points)
      .def_readwrite("max_marker_points", &IdentificationSampling::max_marker_points)
      .def_readwrite("max_head_points", &IdentificationSampling::max_head_points)
      .def_readwrite("min_outlier_mm", &IdentificationSampling::min_outlier_mm)
      .def_readwrite("marker_ring_px", &IdentificationSampling::marker_ring_px)
      .def_readwrite("min_marker_head_fraction", &IdentificationSampling::min_marker_head_fraction)
      .def_readwrite("max_sticker_curvature_per_mm",
                     &IdentificationSampling::max_sticker_curvature_per_mm)
      .def_readwrite("intensity_ab", &IdentificationSampling::intensity_ab);
  OptionsClass<IdentificationOptions>(m, "IdentificationOptions", "IdentifyDepthModel options")
      .def_readwrite("marker_thickness_mm", &IdentificationOptions::marker_thickness_mm)
      .def_readwrite("huber_scale_mm", &IdentificationOptions::huber_scale_mm)
      .def_readwrite("max_correctness_frames", &IdentificationOptions::max_correctness_frames)
      .def_readwrite("reject_outlier_markers", &IdentificationOptions::reject_outlier_markers)
      .def_readwrite("marker_outlier_spreads", &IdentificationOptions::marker_outlier_spreads)
      .def_readwrite("min_marker_outlier_mm", &IdentificationOptions::min_marker_outlier_mm)
      .def_readwrite("difference_steps", &IdentificationOptions::difference_steps)
      .def_property(
          "max_iterations", [](const IdentificationOptions& o) { return o.lm.max_iterations; },
          [](IdentificationOptions& o, int n) { o.lm.max_iterations = n; },
          "Levenberg-Marquardt iterations")
      .def_property(
          "correctness_max_distance_mm",
          [](const IdentificationOptions& o) { return o.correctness.max_distance_mm; },
          [](IdentificationOptions& o, double d) { o.correctness.max_distance_mm = d; },
          "Err_C distance cap [mm]");
}

void DefineIdentificationFrame(py::module_& m) {
  py::class_<IdentificationFrame>(m, "IdentificationFrame",
                                  "the samples of one frame that Eq. (5-7) need")
      .def_readonly("index", &IdentificationFrame::index)
      .def_property_readonly("marker_patches",
                             [](const IdentificationFrame& f) { return f.markers.size(); })
      .def_property_readonly("head_samples",
                             [](const IdentificationFrame& f) { return f.head.size(); })
      .def_property_readonly(
          "marker_points",
          [](const IdentificationFrame& f) { return ArrayFromPoints(f.marker_points); },
          "(N, 3) Eq. (2)-corrected marker points in ahat [mm]")
      .def_property_readonly("world_from_ahat", [](const IdentificationFrame& f) {
        return OptionalArrayFromRigid(f.world_from_ahat);
      });
  m.def(
      "prepare_identification_frame",
      [](const AhatFrame& frame, const AhatCamera& camera,
         const std::optional<MarkerRangeModel>& marker_model, int index,
         const std::optional<IdentificationSampling>& sampling) {
        return PrepareIdentificationFrame(frame, camera, marker_model.value_or(MarkerRangeModel{}),
                                          index, sampling.value_or(IdentificationSampling{}));
      },
      py::arg("frame"), py::arg("camera"), py::arg("marker_model") = py::none(),
      py::arg("index") = 0, py::arg("sampling") = py::none(),
      "segment, correct markers by Eq. (2), sample the head (PrepareIdentificationFrame)");
}

}  // namespace

void DefineIdentification(py::module_& m) {
  DefineIdentificationOptions(m);
  DefineIdentificationFrame(m);
  m.def(
      "identify_depth_model",
      [](const Frames& frames, const std::optional<DepthErrorModel>& start,
         const std::optional<IdentificationOptions>& options,
         const std::optional<TriangleMesh>& skin, const std::optional<py::list>& image_from_ahat) {
        Target target;
        MakeTarget(target, frames, skin, image_from_ahat);
        return IdentifyDepthModel(frames, target.get(), start.value_or(DepthErrorModel{}),
                                  options.value_or(IdentificationOptions{}));
      },
      py::arg("frames"), py::arg("start") = py::none(), py::arg("options") = py::none(),
      py::arg("skin") = py::none(), py::arg("image_from_ahat") = py::none(),
      "Eq. (7) minimised from `start` (its variant is kept): Err_S alone, plus Err_C (Eq. 5) "
      "when the CT skin (Mesh in image) and image_from_ahat per frame are given "
      "(IdentifyDepthModel); the result's .report holds the fit");
  m.def(
      "identification_cost",
      [](const Frames& frames, const DepthErrorModel& model,
         const std::optional<IdentificationOptions>& options,
         const std::optional<TriangleMesh>& skin, const std::optional<py::list>& image_from_ahat) {
        Target target;
        MakeTarget(target, frames, skin, image_from_ahat);
        const IdentificationCost cost = EvaluateIdentificationCost(
            frames, target.get(), model, options.value_or(IdentificationOptions{}));
        py::dict out;
        out["total"] = cost.total;
        out["frames"] = FrameResidualList(cost.frames);
        return out;
      },
      py::arg("frames"), py::arg("model"), py::arg("options") = py::none(),
      py::arg("skin") = py::none(), py::arg("image_from_ahat") = py::none(),
      "Eq. (7) [mm^2] and the per-frame Err_C / Err_S for a given model "
      "(EvaluateIdentificationCost): {total, frames}");
  m.def(
      "initial_image_from_ahat",
      [](const Frames& frames, const TriangleMesh& skin, const DepthErrorModel& model) {
        const InitialPoseResult r = InitialImageFromAhat(frames, SurfaceIndex(skin), model);
        py::list poses;
        for (const std::optional<Rigid3d>& pose : r.image_from_ahat) {
          poses.append(OptionalArrayFromRigid(pose));
        }
        return py::make_tuple(poses, r.reference_frame);
      },
      py::arg("frames"), py::arg("skin"), py::arg("model"),
      "image_from_ahat per frame (None without a world pose) by registering the skin to the "
      "model-corrected head of a reference frame (InitialImageFromAhat) -> (poses, reference)");
  m.def("default_model_candidates", &DefaultModelCandidates,
        "the variants compared by cross-validation: theta, theta^2, 1 - cos theta, theta + AB");
  m.def(
      "cross_validate_models",
      [](const Frames& frames, const std::vector<DepthErrorModel>& candidates, int folds,
         const std::optional<IdentificationOptions>& options) {
        return CrossValidateModels(frames, nullptr, candidates, folds,
                                   options.value_or(IdentificationOptions{}));
      },
      py::arg("frames"), py::arg("candidates"), py::arg("folds") = 4,
      py::arg("options") = py::none(),
      "held-out Err_S^2 [mm^2] per candidate (CrossValidateModels, smoothness only): [(name, "
      "cost)]");
}

}  // namespace tofnav::python
