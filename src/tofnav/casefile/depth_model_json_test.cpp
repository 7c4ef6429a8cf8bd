// SPDX-License-Identifier: BSD-3-Clause
// depth_model.json and f_rf JSON: round trips and every class of malformed input.
#include "tofnav/casefile/depth_model_json.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

#include "tofnav/io/io_error.hpp"

namespace tofnav {
namespace {

DepthModelFile Example() {
  DepthModelFile file;
  file.model.angle_term = AngleTerm::kOneMinusCos;
  file.model.use_intensity = true;
  file.model.c1_mm = 9.25;
  file.model.c2 = 0.0071;
  file.model.c3_mm = 5.5;
  file.model.c4_mm = -0.3;
  file.model.multipath.enabled = true;
  file.model.multipath.ab_scale = 71.5;
  file.model.multipath.passes = 3;
  file.model.multipath.damped = false;  // not the default, so the round trip shows it was read
  file.model.multipath.skin_delay_mm = 6.25;  // likewise
  file.model.report.method = "levenberg-marquardt";
  file.model.report.costs = "smoothness";
  file.model.report.frames = {{3, -1.0, 0.42, 4}, {7, 0.3, 0.5, 3}};
  file.model.report.standard_errors = {0.1, 1e-4, std::nan(""), 0.2};
  file.model.report.cross_validation = {{"linear-theta", 0.25}};
  MarkerRangeModel range;
  range.bias_mm.x = {300.0, 500.0, 700.0};
  range.bias_mm.value = {0.0, 2.0, 4.0};
  range.bias_mm.second_derivative = {0.0, 0.0, 0.0};
  range.smoothing_p = 0.5;
  range.entrance_gain_mm_per_rad = 1.9;  // the tape's entrance-angle term travels with f_rf
  file.marker_range = range;
  return file;
}

TEST(DepthModelJson, RoundTripsModelRangeAndReport) {
  const DepthModelFile in = Example();
  const DepthModelFile out = DecodeDepthModelJson(EncodeDepthModelJson(in));
  EXPECT_EQ(out.model.angle_term, AngleTerm::kOneMinusCos);
  EXPECT_TRUE(out.model.use_intensity);
  EXPECT_EQ(out.model.c1_mm, 9.25);  // JSON keeps doubles exactly (shortest round-trip form)
  EXPECT_EQ(out.model.c2, 0.0071);
  EXPECT_EQ(out.model.c4_mm, -0.3);
  ASSERT_TRUE(out.marker_range.has_value());
  EXPECT_EQ(out.marker_range->bias_mm.value, in.marker_range->bias_mm.value);
  EXPECT_EQ(out.model.report.frames.size(), 2u);
  EXPECT_EQ(out.model.report.frames[1].markers, 3);
  EXPECT_TRUE(std::isnan(out.model.report.standard_errors[2]));
  EXPECT_EQ(out.model.report.cross_validation[0].first, "linear-theta");
  EXPECT_EQ(out.marker_range->bias_mm.x, in.marker_range->bias_mm.x);
  EXPECT_EQ(out.marker_range->entrance_gain_mm_per_rad, 1.9);
  EXPECT_TRUE(out.model.multipath.enabled);
  EXPECT_EQ(out.model.multipath.ab_scale, 71.5);
  EXPECT_EQ(out.model.multipath.passes, 3);
  EXPECT_FALSE(out.model.multipath.damped);
  EXPECT_EQ(out.model.multipath.skin_delay_mm, 6.25);
  EXPECT_EQ(out.model.multipath.source_stride_px, in.model.multipath.source_stride_px);
}

TEST(DepthModelJson, WritesTheOptionsAndTheReaderIgnoresThem) {
  const nlohmann::ordered_json options{{"max-frames", 300}, {"model", "theta"}};
  const std::string text = EncodeDepthModelJson(Example(), &options);
  EXPECT_EQ(nlohmann::ordered_json::parse(text)["options"], options);
  EXPECT_EQ(DecodeDepthModelJson(text).model.c1_mm, 9.25);
}

TEST(DepthModelJson, AFileWithoutMultipathCorrectsWithoutIt) {
  // Files written before the multipath removal existed: their coefficients were fitted on the
  // measured ranges, so correction must not remove anything first.
  std::string text = EncodeDepthModelJson(Example());
  const auto at = text.find("\"multipath\"");
  ASSERT_NE(at, std::string::npos);
  const auto end = text.find('}', at);
  text.erase(at, end + 1 - at);
  // The member was the last of "model": drop the comma left before it.
  const auto comma = text.rfind(',', at);
  text.erase(comma, 1);
  EXPECT_FALSE(DecodeDepthModelJson(text).model.multipath.enabled);
}

TEST(DepthModelJson, TheIntensityFormRoundTripsAndAnOlderFileHasTheRangeTerm) {
  DepthModelFile in = Example();
  in.model.use_range_term = false;
  in.model.c2 = 0.0;
  std::string text = EncodeDepthModelJson(in);
  const DepthModelFile out = DecodeDepthModelJson(text);
  EXPECT_FALSE(out.model.use_range_term);
  EXPECT_EQ(out.model.Name(), "intensity-1-cos");
  // A C2 in a file that says it has no range term is a contradiction, not a value to drop.
  const std::string with_c2 =
      std::string(text).replace(text.find("\"c2\": 0.0"), 10, "\"c2\": 0.5");
  EXPECT_THROW(DecodeDepthModelJson(with_c2), IoError);
  // Files written before the member existed fitted Eq. (3) with its C2.
  const std::string member = "\"use_range_term\": false,";
  const auto at = text.find(member);
  ASSERT_NE(at, std::string::npos);
  text.erase(at, member.size());
  EXPECT_TRUE(DecodeDepthModelJson(text).model.use_range_term);
}

TEST(DepthModelJson, TheCyclicErrorRoundTripsAndAnOlderFileHasNone) {
  DepthModelFile in = Example();
  in.model.cyclic = {.amplitude_mm = 0.9, .period_mm = 351.7, .phase_rad = -0.25};
  std::string text = EncodeDepthModelJson(in);
  const DepthModelFile out = DecodeDepthModelJson(text);
  EXPECT_EQ(out.model.cyclic.amplitude_mm, 0.9);
  EXPECT_EQ(out.model.cyclic.period_mm, 351.7);
  EXPECT_EQ(out.model.cyclic.phase_rad, -0.25);
  // A negative amplitude is refused, naming the model.
  std::string negative = text;
  negative.replace(negative.find("\"amplitude_mm\": 0.9"), 19, "\"amplitude_mm\": -1");
  EXPECT_THROW(DecodeDepthModelJson(negative), IoError);
  // Files written before the member existed correct without a cyclic term.
  nlohmann::json older = nlohmann::json::parse(text);
  older["model"].erase("cyclic_error");
  EXPECT_FALSE(DecodeDepthModelJson(older.dump()).model.cyclic.enabled());
}

TEST(DepthModelJson, TheAngleReferenceRoundTripsAndAnOlderFileHasZero) {
  DepthModelFile in = Example();
  in.model.theta_reference_rad = 0.61;
  const std::string text = EncodeDepthModelJson(in);
  EXPECT_EQ(DecodeDepthModelJson(text).model.theta_reference_rad, 0.61);
  // Outside [0, pi/2] it is refused, naming the model.
  nlohmann::json bad = nlohmann::json::parse(text);
  bad["model"]["coefficients"]["theta_reference_rad"] = 2.0;
  EXPECT_THROW(DecodeDepthModelJson(bad.dump()), IoError);
  // Files written before the member existed wrote C1 at theta = 0.
  nlohmann::json older = nlohmann::json::parse(text);
  older["model"]["coefficients"].erase("theta_reference_rad");
  EXPECT_EQ(DecodeDepthModelJson(older.dump()).model.theta_reference_rad, 0.0);
}

TEST(DepthModelJson, AnOlderFileWithoutTheDampingIsReadUndamped) {
  // Its coefficients were identified with the undamped fixed point: correct as they were fitted.
  DepthModelFile in = Example();
  in.model.multipath.damped = true;
  nlohmann::json text = nlohmann::json::parse(EncodeDepthModelJson(in));
  EXPECT_TRUE(DecodeDepthModelJson(text.dump()).model.multipath.damped);
  text["model"]["multipath"].erase("damped");
  EXPECT_FALSE(DecodeDepthModelJson(text.dump()).model.multipath.damped);
  text["model"]["multipath"]["damped"] = 1;
  EXPECT_THROW(DecodeDepthModelJson(text.dump()), IoError);
}

TEST(DepthModelJson, AnOlderFileWithoutTheSkinDelayIsReadWithoutIt) {
  // Identified before the indirect light carried the skin's delay (docs/correction.md 7.3): its
  // removal is repeated without it; a delay outside [0, 100] mm is refused, naming the field.
  nlohmann::json text = nlohmann::json::parse(EncodeDepthModelJson(Example()));
  EXPECT_EQ(DecodeDepthModelJson(text.dump()).model.multipath.skin_delay_mm, 6.25);
  text["model"]["multipath"].erase("skin_delay_mm");
  EXPECT_EQ(DecodeDepthModelJson(text.dump()).model.multipath.skin_delay_mm, 0.0);
  text["model"]["multipath"]["skin_delay_mm"] = -1.0;
  try {
    DecodeDepthModelJson(text.dump());
    ADD_FAILURE() << "a negative delay was accepted";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("skin_delay_mm"), std::string::npos) << e.what();
  }
}

TEST(DepthModelJson, MalformedInputThrowsIoErrorNamingTheProblem) {
  const std::string good = EncodeDepthModelJson(Example());
  auto fails_with = [](const std::string& text, const std::string& needle) {
    try {
      DecodeDepthModelJson(text, "m.json");
    } catch (const IoError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("m.json"), std::string::npos) << what;
      EXPECT_NE(what.find(needle), std::string::npos) << what;
      return;
    }
    ADD_FAILURE() << "no IoError for " << text.substr(0, 60);
  };
  fails_with(good.substr(0, good.size() / 2), "malformed JSON");
  fails_with("[]", "expected a JSON object");
  fails_with(R"({"format": "x", "version": 1})", "format");
  fails_with(R"({"format": "tofnav-depth-model", "version": 2})", "version");
  fails_with(R"({"format": "tofnav-depth-model", "version": 1})", "missing \"model\"");
  std::string bad_term = good;
  bad_term.replace(bad_term.find("\"1-cos\""), 7, "\"cos\"");
  fails_with(bad_term, "angle_term");
  std::string bad_c2 = good;
  bad_c2.replace(bad_c2.find("\"c2\": 0.0071"), 12, "\"c2\": -2");
  fails_with(bad_c2, "c2");
  std::string bad_knots = good;
  bad_knots.replace(bad_knots.find("700.0"), 5, "100.0");
  fails_with(bad_knots, "marker range");
  std::string bad_passes = good;
  bad_passes.replace(bad_passes.find("\"passes\": 3"), 11, "\"passes\": 0");
  fails_with(bad_passes, "passes");
  std::string bad_stride = good;
  const std::string stride = "\"source_stride_px\": 16";
  bad_stride.replace(bad_stride.find(stride), stride.size(), "\"source_stride_px\": 1.5");
  fails_with(bad_stride, "integer");
}

}  // namespace
}  // namespace tofnav
