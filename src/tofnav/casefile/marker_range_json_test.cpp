// SPDX-License-Identifier: BSD-3-Clause
// f_rf JSON: the curve evaluates identically after a round trip; malformed files are rejected.
#include "tofnav/casefile/marker_range_json.hpp"

#include <gtest/gtest.h>

#include "tofnav/io/io_error.hpp"

namespace tofnav {
namespace {

MarkerRangeFile Fitted() {
  std::vector<MarkerRangeSample> samples;
  for (int i = 0; i < 40; ++i) {
    const double d = 300.0 + 10.0 * i;
    samples.push_back({d, 1.0 + 0.01 * (d - 300.0) + 0.1 * std::sin(0.37 * i), 1.0});
  }
  MarkerRangeFile file;
  const MarkerRangeFitResult fit = FitMarkerRangeModel(samples);
  file.model = fit.model;
  file.fit.samples = 40;
  file.fit.frames = 10;
  file.fit.rms_residual_mm = fit.rms_residual_mm;
  file.fit.effective_dof = fit.fit.effective_dof;
  return file;
}

TEST(MarkerRangeJson, RoundTripEvaluatesIdentically) {
  const MarkerRangeFile file = Fitted();
  const MarkerRangeFile back = DecodeMarkerRangeJson(EncodeMarkerRangeJson(file));
  EXPECT_EQ(back.model.smoothing_p, file.model.smoothing_p);
  EXPECT_EQ(back.fit.samples, 40);
  EXPECT_EQ(back.fit.frames, 10);
  EXPECT_EQ(back.fit.smoothing, "gcv");
  for (double d = 200.0; d <= 800.0; d += 7.3) {  // inside and outside the knots
    EXPECT_EQ(back.model.BiasMm(d), file.model.BiasMm(d)) << d;
  }
}

TEST(MarkerRangeJson, TheStagesCyclicErrorRoundTripsAndIsAbsentUnlessMeasured) {
  MarkerRangeFile file = Fitted();
  EXPECT_FALSE(DecodeMarkerRangeJson(EncodeMarkerRangeJson(file)).cyclic_error.has_value());
  file.cyclic_error = StageCyclicErrorInfo{{1.07, 1055.0 / 3.0, -2.67}, 0.008, 0.006, 55772, 451.6};
  const MarkerRangeFile back = DecodeMarkerRangeJson(EncodeMarkerRangeJson(file));
  ASSERT_TRUE(back.cyclic_error.has_value());
  EXPECT_EQ(back.cyclic_error->cyclic, file.cyclic_error->cyclic);
  EXPECT_EQ(back.cyclic_error->amplitude_sd_mm, 0.008);
  EXPECT_EQ(back.cyclic_error->plate_samples, 55772);
  EXPECT_EQ(back.cyclic_error->span_mm, 451.6);
}

TEST(MarkerRangeJson, EmptyCurveIsNoCorrection) {
  const MarkerRangeFile back = DecodeMarkerRangeJson(EncodeMarkerRangeJson({}));
  EXPECT_TRUE(back.model.empty());
  EXPECT_EQ(CorrectMarkerRange(432.0, back.model), 432.0);
}

void ExpectError(const std::string& text, const std::string& needle) {
  try {
    DecodeMarkerRangeJson(text, "frf.json");
    ADD_FAILURE() << "no error for: " << text;
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("frf.json"), std::string::npos) << e.what();
  }
}

TEST(MarkerRangeJson, RejectsMalformedFiles) {
  const std::string head = R"({"format": "tofnav-marker-range-error", )";
  ExpectError("[1, 2", "malformed JSON");
  ExpectError(R"({"format": "other"})", "tofnav-marker-range-error");
  ExpectError(head + R"("range_unit": "m"})", "range_unit");
  ExpectError(head + R"("knots_mm": [], "bias_mm": [], "second_derivative_per_mm": [], )" +
                  R"("cyclic_error": {"amplitude_mm": 1.0, "phase_rad": 0.0}})",
              "cyclic_error");
  ExpectError(head + R"("knots_mm": [], "bias_mm": [], "second_derivative_per_mm": [], )" +
                  R"("cyclic_error": {"amplitude_mm": -1.0, "period_mm": 351.7, "phase_rad": 0}})",
              "cyclic_error");
  ExpectError(head + R"("knots_mm": [1, 2]})", "bias_mm");
  ExpectError(head + R"("knots_mm": [1, 2], "bias_mm": [0], "second_derivative_per_mm": [0, 0]})",
              "equal lengths");
  ExpectError(
      head + R"("knots_mm": [2, 1], "bias_mm": [0, 0], "second_derivative_per_mm": [0, 0]})",
      "strictly increasing");
  ExpectError(
      head + R"("knots_mm": [1, 2], "bias_mm": [0, "a"], "second_derivative_per_mm": [0, 0]})",
      "finite numbers");
  ExpectError(
      head + R"("knots_mm": [1, 2], "bias_mm": [0, 0], "second_derivative_per_mm": [1, 0]})",
      "natural spline");
}

}  // namespace
}  // namespace tofnav
