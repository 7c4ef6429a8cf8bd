// SPDX-License-Identifier: BSD-3-Clause
// Depth correction: f_rf (Eq. 1-2), the surface model (Eq. 3-4), normals, segmentation, a frame.
#include <pybind11/stl.h>

#include <span>
#include <vector>

#include "convert.hpp"
#include "defines.hpp"
#include "options.hpp"
#include "tofnav/correction/correct_range.hpp"
#include "tofnav/correction/depth_error_model.hpp"
#include "tofnav/correction/marker_range_model.hpp"
#include "tofnav/correction/multipath_correction.hpp"

namespace tofnav::python {

py::list FrameResidualList(const std::vector<FrameResidual>& frames) {
  py::list out;
  for (const FrameResidual& f : frames) {
    py::dict frame;
    frame["frame"] = f.frame;
    frame["err_c_mm"] = f.err_c_mm;
    frame["err_s_mm"] = f.err_s_mm;
    frame["markers"] = f.markers;
    out.append(frame);
  }
  return out;
}

namespace {

py::dict FitReportDict(const DepthErrorModel& model) {
  const DepthModelFitReport& r = model.report;
  py::dict out;
  out["method"] = r.method;
  out["costs"] = r.costs;
  out["frames_used"] = r.frames_used;
  out["frames_left_out"] = r.frames_left_out;
  out["marker_observations"] = r.marker_observations;
  out["marker_observations_rejected"] = r.marker_observations_rejected;
  out["marker_observations_curved"] = r.marker_observations_curved;
  out["evaluations"] = r.evaluations;
  out["initial_cost"] = r.initial_cost;
  out["final_cost"] = r.final_cost;
  out["seconds"] = r.seconds;
  out["standard_errors"] = r.standard_errors;
  out["cross_validation"] = r.cross_validation;
  out["frames"] = FrameResidualList(r.frames);
  return out;
}

DepthErrorModel MakeModel(double c1_mm, double c2, double c3_mm, double c4_mm,
                          const std::string& angle_term, bool use_intensity, double ab_reference,
                          bool use_range_term) {
  DepthErrorModel model{.angle_term = ParseAngleTerm(angle_term),
                        .use_intensity = use_intensity,
                        .use_range_term = use_range_term,
                        .c1_mm = c1_mm,
                        .c2 = c2,
                        .c3_mm = c3_mm,
                        .c4_mm = c4_mm,
                        .ab_reference = ab_reference};
  model.Check();
  return model;
}

void DefineDepthModel(py::module_& m) {
  py::class_<DepthErrorModel>(m, "DepthErrorModel",
                              "surface depth error delta_d = C1 + C2 d + C3 g(theta) [+ C4 "
                              "ln(AB_ref / AB)] (Eq. 3) and its inverse (Eq. 4)")
      .def(py::init(&MakeModel), py::arg("c1_mm") = 0.0, py::arg("c2") = 0.0,
           py::arg("c3_mm") = 0.0, py::arg("c4_mm") = 0.0, py::arg("angle_term") = "theta",
           py::arg("use_intensity") = false, py::arg("ab_reference") = 130.0,
           py::arg("use_range_term") = true)
      .def_readwrite("c1_mm", &DepthErrorModel::c1_mm)
      .def_readwrite("c2", &DepthErrorModel::c2)
      .def_readwrite("c3_mm", &DepthErrorModel::c3_mm)
      .def_readwrite("c4_mm", &DepthErrorModel::c4_mm)
      .def_readwrite("use_intensity", &DepthErrorModel::use_intensity)
      .def_readwrite("use_range_term", &DepthErrorModel::use_range_term,
                     "False: C2 held at 0 (the intensity form, tofnav's default)")
      .def_readwrite("ab_reference", &DepthErrorModel::ab_reference)
      .def_readwrite("theta_reference_rad", &DepthErrorModel::theta_reference_rad)
      .def_readwrite("multipath", &DepthErrorModel::multipath,
                     "MultipathCorrectionOptions applied before Eq. (4) (off unless identified so)")
      .def_property(
          "angle_term", [](const DepthErrorModel& d) { return AngleTermName(d.angle_term); },
          [](DepthErrorModel& d, const std::string& name) { d.angle_term = ParseAngleTerm(name); },
          "'theta' (paper), 'theta2' or '1-cos'")
      .def_property_readonly("name", &DepthErrorModel::Name)
      .def_property_readonly("parameters", &ModelParameters,
                             "the free parameters: [C1(, C2), C3(, C4)]")
      .def_property_readonly("report", &FitReportDict,
                             "the identification's fit report as a dict (empty when not fitted)")
      .def("bias_mm", py::vectorize(&DepthErrorModel::BiasMm), py::arg("true_range_mm"),
           py::arg("theta_rad"), py::arg("ab") = 0.0, "Eq. (3), element-wise")
      .def("correct_range_mm", py::vectorize(&DepthErrorModel::CorrectRangeMm),
           py::arg("measured_range_mm"), py::arg("theta_rad"), py::arg("ab") = 0.0,
           "Eq. (4), element-wise");
}

py::tuple FitMarkerRange(const ArrayD& range_mm, const ArrayD& error_mm, const py::object& weights,
                         std::optional<double> smoothing_p) {
  if (range_mm.ndim() != 1 || error_mm.ndim() != 1 || range_mm.size() != error_mm.size()) {
    throw py::value_error("range_mm and error_mm must be 1-D arrays of one length");
  }
  std::vector<MarkerRangeSample> samples(static_cast<std::size_t>(range_mm.size()));
  const ArrayD w = weights.is_none() ? ArrayD() : weights.cast<ArrayD>();
  if (!weights.is_none() && (w.ndim() != 1 || w.size() != range_mm.size())) {
    throw py::value_error("weights must be a 1-D array as long as range_mm");
  }
  for (py::ssize_t i = 0; i < range_mm.size(); ++i) {
    samples[static_cast<std::size_t>(i)] = {range_mm.at(i), error_mm.at(i),
                                            weights.is_none() ? 1.0 : w.at(i)};
  }
  const MarkerRangeFitResult r = FitMarkerRangeModel(samples, {.smoothing_p = smoothing_p});
  py::dict fit;
  fit["smoothing_p"] = r.fit.smoothing_p;
  fit["effective_dof"] = r.fit.effective_dof;
  fit["gcv_score"] = r.fit.gcv_score;
  fit["rss_weighted"] = r.fit.rss_weighted;
  fit["site_count"] = r.fit.site_count;
  fit["rms_residual_mm"] = r.rms_residual_mm;
  return py::make_tuple(r.model, fit);
}

void DefineMarkerRange(py::module_& m) {
  py::class_<MarkerRangeModel>(m, "MarkerRangeModel",
                               "f_rf(d), the retro-reflector range error (Eq. 1); empty = 0")
      .def(py::init<>())
      .def_property_readonly("empty", &MarkerRangeModel::empty)
      .def_readonly("smoothing_p", &MarkerRangeModel::smoothing_p)
      .def_property_readonly(
          "knots_mm", [](const MarkerRangeModel& f) { return py::array(py::cast(f.bias_mm.x)); })
      .def_readonly("entrance_gain_mm_per_rad", &MarkerRangeModel::entrance_gain_mm_per_rad)
      .def("bias_mm", py::vectorize([](const MarkerRangeModel* f, double range_mm) {
             return f->BiasMm(range_mm);
           }),
           py::arg("range_mm"),
           "f_rf at the measured surface range [mm] (entrance angle 0), element-wise")
      .def("correct_range_mm", py::vectorize([](const MarkerRangeModel* f, double range_mm) {
             return CorrectMarkerRange(range_mm, *f);
           }),
           py::arg("range_mm"), "Eq. (2): d - f_rf(d), element-wise")
      .def(
          "correct_points",
          [](const MarkerRangeModel& f, const ArrayD& points) {
            Points3d out = PointsFromArray(points, "points");
            for (Eigen::Vector3d& p : out) p = CorrectMarkerPoint(p, f);
            return ArrayFromPoints(out);
          },
          py::arg("points"), "Eq. (2) on (N, 3) points in ahat [mm]");
  m.def("fit_marker_range_model", &FitMarkerRange, py::arg("range_mm"), py::arg("error_mm"),
        py::arg("weights") = py::none(), py::arg("smoothing_p") = py::none(),
        "Eq. (1) smoothing spline of (measured range, error) samples -> (MarkerRangeModel, fit "
        "dict); p by GCV unless given (FitMarkerRangeModel)");
  m.def("correct_marker_ranges", &CorrectMarkerRanges, py::arg("markers"), py::arg("model"),
        "Eq. (2) on detected markers (CorrectMarkerRanges): corrected copies");
}

void DefineOptions(py::module_& m) {
  OptionsClass<HeadRegionOptions>(m, "HeadRegionOptions",
                                  "SelectHeadRegion options (enabled = False: the whole frame)")
      .def_readwrite("enabled", &HeadRegionOptions::enabled)
      .def_readwrite("plane_tolerance_mm", &HeadRegionOptions::plane_tolerance_mm)
      .def_readwrite("min_plane_area_mm2", &HeadRegionOptions::min_plane_area_mm2)
      .def_readwrite("max_planes", &HeadRegionOptions::max_planes)
      .def_readwrite("min_component_area_mm2", &HeadRegionOptions::min_component_area_mm2);
  OptionsClass<SegmentationOptions>(m, "SegmentationOptions", "SegmentFrame options")
      .def_readwrite("marker_ab_threshold", &SegmentationOptions::marker_ab_threshold)
      .def_readwrite("min_marker_area_px", &SegmentationOptions::min_marker_area_px)
      .def_readwrite("max_marker_area_px", &SegmentationOptions::max_marker_area_px)
      .def_readwrite("transition_dilation_px", &SegmentationOptions::transition_dilation_px)
      .def_readwrite("min_range_mm", &SegmentationOptions::min_range_mm)
      .def_readwrite("max_range_mm", &SegmentationOptions::max_range_mm)
      .def_readwrite("roi_radius_mm", &SegmentationOptions::roi_radius_mm)
      .def_readwrite("head_region", &SegmentationOptions::head_region);
  OptionsClass<RangeNormalOptions>(m, "RangeNormalOptions", "ComputeRangeNormals options")
      .def_readwrite("smoothing_radius_px", &RangeNormalOptions::smoothing_radius_px)
      .def_readwrite("difference_step_px", &RangeNormalOptions::difference_step_px)
      .def_readwrite("edge_abs_mm", &RangeNormalOptions::edge_abs_mm)
      .def_readwrite("edge_rel", &RangeNormalOptions::edge_rel);
  OptionsClass<MultipathCorrectionOptions>(m, "MultipathCorrectionOptions",
                                           "RemoveMultipath options (docs/correction.md 7)")
      .def_readwrite("enabled", &MultipathCorrectionOptions::enabled)
      .def_readwrite("ab_scale", &MultipathCorrectionOptions::ab_scale)
      .def_readwrite("falloff_power", &MultipathCorrectionOptions::falloff_power)
      .def_readwrite("max_albedo", &MultipathCorrectionOptions::max_albedo)
      .def_readwrite("source_stride_px", &MultipathCorrectionOptions::source_stride_px)
      .def_readwrite("receiver_stride_px", &MultipathCorrectionOptions::receiver_stride_px)
      .def_readwrite("min_cos_incidence", &MultipathCorrectionOptions::min_cos_incidence)
      .def_readwrite("max_indirect_ratio", &MultipathCorrectionOptions::max_indirect_ratio)
      .def_readwrite("passes", &MultipathCorrectionOptions::passes)
      .def_readwrite("alias_mm", &MultipathCorrectionOptions::alias_mm)
      .def_readwrite("skin_delay_mm", &MultipathCorrectionOptions::skin_delay_mm);
  OptionsClass<IntensityAbOptions>(m, "IntensityAbOptions",
                                   "the AB the intensity term reads (docs/correction.md 2.10)")
      .def_readwrite("window_mean", &IntensityAbOptions::window_mean)
      .def_readwrite("radius_px", &IntensityAbOptions::radius_px)
      .def_readwrite("same_surface_mm_per_px", &IntensityAbOptions::same_surface_mm_per_px);
  OptionsClass<CorrectRangeOptions>(m, "CorrectRangeOptions", "CorrectFrame options")
      .def_readwrite("marker_model", &CorrectRangeOptions::marker_model)
      .def_readwrite("segmentation", &CorrectRangeOptions::segmentation)
      .def_readwrite("normals", &CorrectRangeOptions::normals)
      .def_readwrite("roi_only", &CorrectRangeOptions::roi_only)
      .def_readwrite("drop_without_normal", &CorrectRangeOptions::drop_without_normal)
      .def_readwrite("max_incidence_rad", &CorrectRangeOptions::max_incidence_rad)
      .def_readwrite("intensity_ab", &CorrectRangeOptions::intensity_ab);
}

py::tuple Normals(const ArrayF& range_mm, const AhatCamera& camera,
                  const std::optional<RangeNormalOptions>& options) {
  const RangeNormals n = ComputeRangeNormals(ImageFromArray<float>(range_mm, "range_mm"), camera,
                                             options.value_or(RangeNormalOptions{}));
  py::array_t<float> normal({n.normal.height(), n.normal.width(), 3});
  for (int v = 0; v < n.normal.height(); ++v) {
    for (int u = 0; u < n.normal.width(); ++u) {
      for (int c = 0; c < 3; ++c) normal.mutable_at(v, u, c) = n.normal(u, v)[c];
    }
  }
  return py::make_tuple(normal, ArrayFromImage(n.incidence_rad));
}

py::tuple Multipath(const ArrayF& range_mm,
                    const py::array_t<std::uint16_t, py::array::c_style | py::array::forcecast>& ab,
                    const AhatCamera& camera,
                    const std::optional<MultipathCorrectionOptions>& options,
                    const std::optional<RangeNormalOptions>& normal_options, bool ab_lossy,
                    const std::optional<ArrayF>& scatter_delay_mm) {
  MultipathCorrectionStats stats;
  std::optional<Image<float>> delay;
  if (scatter_delay_mm) delay = ImageFromArray<float>(*scatter_delay_mm, "scatter_delay_mm");
  const Image<float> out = RemoveMultipath(
      ImageFromArray<float>(range_mm, "range_mm"), ImageFromArray<std::uint16_t>(ab, "ab"), camera,
      options.value_or(MultipathCorrectionOptions{}), normal_options.value_or(RangeNormalOptions{}),
      {.ab_square_code = ab_lossy, .scatter_delay_mm = delay ? &*delay : nullptr}, &stats);
  py::dict s;
  s["pixels_corrected"] = stats.pixels_corrected;
  s["pixels_dropped"] = stats.pixels_dropped;
  s["mean_shift_mm"] = stats.mean_shift_mm;
  return py::make_tuple(ArrayFromImage(out), s);
}

py::dict SegmentationDict(const FrameSegmentation& s) {
  py::list markers;
  for (const MarkerArea& area : s.markers) {
    py::array_t<int> pixels({static_cast<py::ssize_t>(area.pixels.size()), py::ssize_t{2}});
    for (std::size_t i = 0; i < area.pixels.size(); ++i) {
      pixels.mutable_at(static_cast<py::ssize_t>(i), 0) = area.pixels[i].x();
      pixels.mutable_at(static_cast<py::ssize_t>(i), 1) = area.pixels[i].y();
    }
    py::dict marker;
    marker["pixels"] = pixels;
    marker["centroid_in_ahat"] = ArrayFromVector(area.centroid_in_ahat);
    markers.append(marker);
  }
  py::dict out;
  out["labels"] = ArrayFromImage(s.labels);
  out["markers"] = markers;
  out["head_pixels"] = s.head_pixels;
  return out;
}

void DefineFrameCorrection(py::module_& m) {
  m.attr("PIXEL_OUTSIDE") = static_cast<int>(PixelClass::kOutside);
  m.attr("PIXEL_HEAD") = static_cast<int>(PixelClass::kHead);
  m.attr("PIXEL_MARKER") = static_cast<int>(PixelClass::kMarker);
  m.attr("PIXEL_TRANSITION") = static_cast<int>(PixelClass::kTransition);
  m.def("range_normals", &Normals, py::arg("range_mm"), py::arg("camera"),
        py::arg("options") = py::none(),
        "(H, W) range [mm] -> ((H, W, 3) float32 unit normals in ahat facing the camera, zero "
        "where none; (H, W) float32 incidence theta [rad], NaN where none) (ComputeRangeNormals)");
  m.def("remove_multipath", &Multipath, py::arg("range_mm"), py::arg("ab"), py::arg("camera"),
        py::arg("options") = py::none(), py::arg("normal_options") = py::none(),
        py::arg("ab_lossy") = false, py::arg("scatter_delay_mm") = py::none(),
        "(H, W) range [mm] (0 = invalid; markers removed), (H, W) AB (ab_lossy: a lossy stream's "
        "square code, Frame.ab_lossy), optional (H, W) scattering delay per pixel [mm] -> "
        "((H, W) float32 range with one-bounce multipath removed, 0 = dropped; stats dict) "
        "(RemoveMultipath, docs/correction.md 7)");
  m.def(
      "segment_frame",
      [](const AhatFrame& frame, const AhatCamera& camera,
         const std::optional<SegmentationOptions>& options) {
        return SegmentationDict(
            SegmentFrame(frame, camera, options.value_or(SegmentationOptions{})));
      },
      py::arg("frame"), py::arg("camera"), py::arg("options") = py::none(),
      "marker / transition / head areas (SegmentFrame): dict with labels (H, W) uint8 "
      "(PIXEL_*), markers [{pixels (K, 2) (u, v), centroid_in_ahat}], head_pixels");
  m.def(
      "correct_frame",
      [](const AhatFrame& frame, const AhatCamera& camera, const DepthErrorModel& model,
         const std::optional<CorrectRangeOptions>& options) {
        const CorrectedFrame c =
            CorrectFrame(frame, camera, model, options.value_or(CorrectRangeOptions{}));
        py::dict out = SegmentationDict(c.segmentation);
        out["range_mm"] = ArrayFromImage(c.range_mm);
        out["incidence_rad"] = ArrayFromImage(c.normals.incidence_rad);
        return out;
      },
      py::arg("frame"), py::arg("camera"), py::arg("model"), py::arg("options") = py::none(),
      "CorrectFrame: segment_frame's dict plus range_mm (corrected, 0 = dropped) and "
      "incidence_rad");
  m.def(
      "correct_range_image",
      [](const AhatFrame& frame, const AhatCamera& camera, const DepthErrorModel& model,
         const std::optional<CorrectRangeOptions>& options) {
        return ArrayFromImage(
            CorrectRangeImage(frame, camera, model, options.value_or(CorrectRangeOptions{})));
      },
      py::arg("frame"), py::arg("camera"), py::arg("model"), py::arg("options") = py::none(),
      "(H, W) float32 corrected range [mm]: Eq. (4) on the head, Eq. (2) on markers, 0 = dropped "
      "(CorrectRangeImage)");
}

}  // namespace

void DefineCorrection(py::module_& m) {
  DefineDepthModel(m);
  DefineMarkerRange(m);
  DefineOptions(m);
  DefineFrameCorrection(m);
}

}  // namespace tofnav::python
