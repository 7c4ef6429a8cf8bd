// SPDX-License-Identifier: BSD-3-Clause
// Materials, sensor effects, camera, timing, CT and plan options of the scenario schema; one
// field table per struct serves both the parser and the truth.json encoder.
#include <filesystem>
#include <functional>
#include <memory>
#include <utility>
#include <vector>

#include "tofnav/recording/hl2ss_calibration.hpp"
#include "tofnav/scenario/scenario_json_internal.hpp"

namespace tofnav::internal {
namespace {

using sim::Material;
constexpr Field<Material> kMaterialFields[] = {
    {"albedo", &Material::albedo},
    {"subsurface_fraction", &Material::subsurface_fraction},
    {"subsurface_delay_ps", &Material::subsurface_delay_ps},
    {"subsurface_angle_gain_per_rad", &Material::subsurface_angle_gain_per_rad},
    {"intensity_bias_gain_mm", &Material::intensity_bias_gain_mm},
    {"model_c1_mm", &Material::model_c1_mm},
    {"model_c2", &Material::model_c2},
    {"model_c3_mm_per_rad", &Material::model_c3_mm_per_rad},
    {"retro_coefficient", &Material::retro_coefficient},
    {"retro_observation_falloff_rad", &Material::retro_observation_falloff_rad},
    {"retro_entrance_cutoff_rad", &Material::retro_entrance_cutoff_rad},
    {"retro_curve_amplitude_mm", &Material::retro_curve_amplitude_mm},
    {"retro_angle_gain_mm_per_rad", &Material::retro_angle_gain_mm_per_rad}};

using sim::RadiometryOptions;
constexpr Field<RadiometryOptions> kRadiometryFields[] = {
    {"ab_scale", &RadiometryOptions::ab_scale},
    {"falloff_power", &RadiometryOptions::falloff_power},
    {"retro_baseline_mm", &RadiometryOptions::retro_baseline_mm}};

using sim::SensorOptions;
constexpr Field<SensorOptions> kSensorFields[] = {
    {"alias_mm", &SensorOptions::alias_mm},
    {"illumination_radius_px", &SensorOptions::illumination_radius_px},
    {"min_valid_ab", &SensorOptions::min_valid_ab},
    {"ab_clip", &SensorOptions::ab_clip},
    {"wiggle_amplitude_mm", &SensorOptions::wiggle_amplitude_mm},
    {"wiggle_period_mm", &SensorOptions::wiggle_period_mm},
    {"wiggle_phase_rad", &SensorOptions::wiggle_phase_rad},
    {"intensity_reference_ab", &SensorOptions::intensity_reference_ab}};

using sim::NoiseOptions;
constexpr Field<NoiseOptions> kNoiseFields[] = {
    {"ab_noise_scale", &NoiseOptions::ab_noise_scale},
    {"depth_sigma_ref_mm", &NoiseOptions::depth_sigma_ref_mm},
    {"depth_sigma_ref_ab", &NoiseOptions::depth_sigma_ref_ab},
    {"depth_sigma_floor_mm", &NoiseOptions::depth_sigma_floor_mm},
    {"depth_sigma_floor_range_mm", &NoiseOptions::depth_sigma_floor_range_mm},
    {"depth_sigma_floor_exponent", &NoiseOptions::depth_sigma_floor_exponent},
    {"depth_correlation_px", &NoiseOptions::depth_correlation_px}};

using sim::ScatterOptions;
constexpr Field<ScatterOptions> kScatterFields[] = {
    {"wide_fraction", &ScatterOptions::wide_fraction},
    {"wide_sigma_px", &ScatterOptions::wide_sigma_px},
    {"narrow_fraction", &ScatterOptions::narrow_fraction},
    {"narrow_sigma_px", &ScatterOptions::narrow_sigma_px}};

using sim::MultipathOptions;
constexpr Field<MultipathOptions> kMultipathFields[] = {{"gain", &MultipathOptions::gain}};

constexpr Field<SyntheticAhatOptions> kCalibrationFields[] = {
    {"focal_px", &SyntheticAhatOptions::focal_px},
    {"aspect_y", &SyntheticAhatOptions::aspect_y},
    {"cubic_rad_per_px3", &SyntheticAhatOptions::cubic_rad_per_px3},
    {"fold_radius_px", &SyntheticAhatOptions::fold_radius_px},
    {"sample_offset_px", &SyntheticAhatOptions::sample_offset_px},
    {"pinhole_focal_px", &SyntheticAhatOptions::pinhole_focal_px}};

using sim::SyntheticCtOptions;
constexpr Field<SyntheticCtOptions> kCtFields[] = {
    {"spacing_mm", &SyntheticCtOptions::spacing_mm},
    {"margin_mm", &SyntheticCtOptions::margin_mm},
    {"air_hu", &SyntheticCtOptions::air_hu},
    {"soft_tissue_hu", &SyntheticCtOptions::soft_tissue_hu},
    {"scalp_mm", &SyntheticCtOptions::scalp_mm},
    {"skull_mm", &SyntheticCtOptions::skull_mm},
    {"skull_table_hu", &SyntheticCtOptions::skull_table_hu},
    {"skull_diploe_hu", &SyntheticCtOptions::skull_diploe_hu},
    {"brain_hu", &SyntheticCtOptions::brain_hu},
    {"ventricle_hu", &SyntheticCtOptions::ventricle_hu},
    {"noise_sigma_hu", &SyntheticCtOptions::noise_sigma_hu}};

using sim::EvdPlanOptions;
constexpr Field<EvdPlanOptions> kPlanFields[] = {
    {"kocher_arc_mm", &EvdPlanOptions::kocher_arc_mm},
    {"kocher_lateral_mm", &EvdPlanOptions::kocher_lateral_mm},
    {"top_posterior_mm", &EvdPlanOptions::top_posterior_mm},
    {"entry_spread_mm", &EvdPlanOptions::entry_spread_mm}};

const std::pair<const char*, sim::RetroCurve> kRetroCurves[] = {
    {"none", sim::RetroCurve::kNone},
    {"linear", sim::RetroCurve::kLinear},
    {"quadratic", sim::RetroCurve::kQuadratic},
    {"sigmoid", sim::RetroCurve::kSigmoid},
    {"wavy", sim::RetroCurve::kWavy}};
const std::pair<const char*, sim::BiasMode> kBiasModes[] = {{"none", sim::BiasMode::kNone},
                                                            {"physical", sim::BiasMode::kPhysical},
                                                            {"model", sim::BiasMode::kModel}};

}  // namespace

std::optional<Material> MaterialPreset(const std::string& name) {
  if (name == "skin") return sim::SkinMaterial();
  if (name == "nylon") return sim::NylonMaterial();
  if (name == "photopolymer") return sim::PhotopolymerMaterial();
  if (name == "pla") return sim::PlaMaterial();
  if (name == "pc_abs") return sim::PcAbsMaterial();
  if (name == "retro_reflective") return sim::RetroReflectiveMaterial();
  if (name == "diffuse") return sim::DiffuseMaterial(0.5);
  if (name == "drape") return sim::DrapeMaterial();
  return std::nullopt;
}

Material ParseMaterial(const Json& json, const std::string& where) {
  JsonFields in(json, where);
  std::string name, preset;
  in.Read("name", name);
  in.Read("preset", preset);
  if (name.empty()) Fail(in.At("name"), "a material needs a name");
  Material material;
  if (!preset.empty()) {
    const std::optional<Material> found = MaterialPreset(preset);
    if (!found) Fail(in.At("preset"), "unknown material preset '" + preset + "'");
    material = *found;
  }
  material.name = name;
  ReadFields(in, material, kMaterialFields);
  in.Read("retro_reflective", material.retro_reflective);
  material.retro_curve = ReadEnum(in, "retro_curve", material.retro_curve, kRetroCurves);
  in.Finish();
  Checked(where, [&] { material.Check(); });
  return material;
}

sim::RenderOptions ParseRender(const Json& json, const std::string& where) {
  JsonFields in(json, where);
  std::string preset = "realistic";
  in.Read("preset", preset);
  sim::RenderOptions options;
  if (preset == "ideal") {
    options = sim::IdealRenderOptions();
  } else if (preset == "model_consistent") {
    options = sim::ModelConsistentRenderOptions();
  } else if (preset != "realistic") {
    Fail(in.At("preset"), "unknown preset '" + preset + "' (realistic, ideal, model_consistent)");
  }
  in.Read("supersampling", options.supersampling);
  in.Read("jitter", options.jitter);
  options.bias_mode = ReadEnum(in, "bias_mode", options.bias_mode, kBiasModes);
  const auto part = [&](const char* key, auto& target, const auto& fields) {
    if (const Json* j = in.Find(key)) {
      JsonFields p(*j, in.At(key));
      ReadFields(p, target, fields);
      if constexpr (std::is_same_v<std::decay_t<decltype(target)>, SensorOptions>) {
        p.Read("floor_depth", target.floor_depth);
      }
      if constexpr (std::is_same_v<std::decay_t<decltype(target)>, MultipathOptions>) {
        p.Read("source_stride_px", target.source_stride_px);
        p.Read("receiver_stride_px", target.receiver_stride_px);
      }
      p.Finish();
    }
  };
  part("radiometry", options.radiometry, kRadiometryFields);
  part("sensor", options.sensor, kSensorFields);
  part("noise", options.noise, kNoiseFields);
  part("scatter", options.scatter, kScatterFields);
  part("multipath", options.multipath, kMultipathFields);
  in.Finish();
  Checked(where, [&] { options.Check(); });
  return options;
}

void ParseCamera(const Json& json, const std::string& where, const std::filesystem::path& base,
                 sim::CameraSetup& camera) {
  JsonFields in(json, where);
  if (const Json* j = in.Find("motion")) camera.motion = ParseMotion(*j, in.At("motion"));
  if (const Json* j = in.Find("calibration")) {
    JsonFields c(*j, in.At("calibration"));
    if (const Json* folder = c.Find("folder")) {
      // A real device: its tables and extrinsics as they are; nothing synthetic may be mixed in.
      if (!folder->is_string()) Fail(c.At("folder"), "expected a path (string)");
      std::filesystem::path path = folder->get<std::string>();
      if (path.is_relative()) path = base / path;
      camera.device = std::make_shared<const AhatCalibration>(ReadHl2ssCalibration(path));
      camera.device_folder = path.string();
      if (j->size() != 1) {
        Fail(in.At("calibration"),
             "'folder' takes the device's calibration as it is; "
             "remove the synthetic camera keys");
      }
    }
    ReadFields(c, camera.calibration, kCalibrationFields);
    c.Read("principal_point_px", camera.calibration.principal_point_px);
    if (const Json* pose = c.Find("rig_from_ahat")) {
      camera.calibration.rig_from_ahat = ParsePose(*pose, c.At("rig_from_ahat"));
    }
    c.Finish();
    Checked(in.At("calibration"), [&] { camera.calibration.Check(); });
  }
  if (const Json* j = in.Find("slam_jitter")) {
    JsonFields s(*j, in.At("slam_jitter"));
    s.Read("translation_sigma_mm", camera.slam.translation_sigma_mm);
    s.Read("rotation_sigma_rad", camera.slam.rotation_sigma_rad);
    s.Finish();
    Checked(in.At("slam_jitter"), [&] { camera.slam.Check(); });
  }
  in.Finish();
}

sim::FrameTimingOptions ParseTiming(const Json& json, const std::string& where) {
  JsonFields in(json, where);
  sim::FrameTimingOptions options;
  in.Read("rate_hz", options.rate_hz);
  in.Read("start_ticks", options.start_ticks);
  in.Read("drop_probability", options.drop_probability);
  in.Read("mean_drop_slots", options.mean_drop_slots);
  in.Read("slot_stride", options.slot_stride);
  in.Read("no_hand_rate_hz", options.no_hand_rate_hz);
  in.Finish();
  Checked(where, [&] { options.Check(); });
  return options;
}

SyntheticCtOptions ParseCtOptions(const Json& json, const std::string& where) {
  JsonFields in(json, where);
  SyntheticCtOptions options;
  ReadFields(in, options, kCtFields);
  in.Read("subsamples", options.subsamples);
  in.Finish();
  Checked(where, [&] { options.Check(); });
  return options;
}

EvdPlanOptions ParsePlanOptions(const Json& json, const std::string& where) {
  JsonFields in(json, where);
  EvdPlanOptions options;
  ReadFields(in, options, kPlanFields);
  in.Finish();
  Checked(where, [&] { options.Check(); });
  return options;
}

OrderedJson MaterialJson(const Material& material) {
  OrderedJson out{{"name", material.name}};
  WriteFields(out, material, kMaterialFields);
  out["retro_reflective"] = material.retro_reflective;
  out["retro_curve"] = EnumName(material.retro_curve, kRetroCurves);
  return out;
}

OrderedJson RenderJson(const sim::RenderOptions& options) {
  OrderedJson out{{"supersampling", options.supersampling},
                  {"jitter", options.jitter},
                  {"bias_mode", EnumName(options.bias_mode, kBiasModes)}};
  WriteFields(out["radiometry"], options.radiometry, kRadiometryFields);
  WriteFields(out["sensor"], options.sensor, kSensorFields);
  out["sensor"]["floor_depth"] = options.sensor.floor_depth;
  WriteFields(out["noise"], options.noise, kNoiseFields);
  WriteFields(out["scatter"], options.scatter, kScatterFields);
  WriteFields(out["multipath"], options.multipath, kMultipathFields);
  out["multipath"]["source_stride_px"] = options.multipath.source_stride_px;
  out["multipath"]["receiver_stride_px"] = options.multipath.receiver_stride_px;
  return out;
}

OrderedJson CalibrationJson(const sim::CameraSetup& camera) {
  OrderedJson out;
  if (camera.device) {
    out["folder"] = camera.device_folder;
    return out;
  }
  const SyntheticAhatOptions& options = camera.calibration;
  WriteFields(out, options, kCalibrationFields);
  out["principal_point_px"] = {options.principal_point_px.x(), options.principal_point_px.y()};
  out["rig_from_ahat"] = MatrixJson(options.rig_from_ahat);
  return out;
}

}  // namespace tofnav::internal
