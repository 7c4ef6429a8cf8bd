// SPDX-License-Identifier: BSD-3-Clause
// Tool poses CSV/JSON: exact round trips and rejection of malformed files with byte offsets.
#include "tofnav/casefile/tool_poses_io.hpp"

#include <gtest/gtest.h>

#include "tofnav/io/io_error.hpp"

namespace tofnav {
namespace {

std::vector<ToolPoseRecord> Records() {
  ToolPoseRecord a;
  a.frame = 7;
  a.host_ticks = 36000123456ULL;
  a.time_s = 3600.0123456;
  a.tool = "reference_left";
  a.status = ToolStatus::kPartiallyOccluded;
  a.markers_used = 3;
  a.marker_count = 4;
  a.fre_mm = 0.123456789;
  a.rotation_sd_deg = 0.3125;
  a.position_sd_mm = 0.1 / 3.0;
  a.filtered_rotation_sd_deg = 0.2 / 3.0;
  a.ahat_from_tool =
      Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())),
              Eigen::Vector3d(-12.5, 40.0 / 3.0, 456.789));
  a.filtered_ahat_from_tool = Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(1, 2, 3));
  a.world_from_tool = Rigid3d(Eigen::Quaterniond(0.5, 0.5, -0.5, 0.5), Eigen::Vector3d(0, 0, 1));
  ToolPoseRecord b;
  b.frame = 8;
  b.host_ticks = 36000345678ULL;
  b.time_s = 3600.0345678;
  b.tool = "pointer";
  b.status = ToolStatus::kAmbiguous;
  b.marker_count = 5;
  b.gated = true;
  return {a, b};
}

void ExpectSamePose(const std::optional<Rigid3d>& a, const std::optional<Rigid3d>& b) {
  ASSERT_EQ(a.has_value(), b.has_value());
  if (!a) return;
  EXPECT_EQ(a->rotation.coeffs(), b->rotation.coeffs());  // round-trip precision: bit exact
  EXPECT_EQ(a->translation, b->translation);
}

void ExpectSame(const std::vector<ToolPoseRecord>& a, const std::vector<ToolPoseRecord>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].frame, b[i].frame);
    EXPECT_EQ(a[i].host_ticks, b[i].host_ticks);
    EXPECT_EQ(a[i].time_s, b[i].time_s);
    EXPECT_EQ(a[i].tool, b[i].tool);
    EXPECT_EQ(a[i].status, b[i].status);
    EXPECT_EQ(a[i].markers_used, b[i].markers_used);
    EXPECT_EQ(a[i].marker_count, b[i].marker_count);
    EXPECT_EQ(a[i].fre_mm, b[i].fre_mm);
    EXPECT_EQ(a[i].gated, b[i].gated);
    ExpectSamePose(a[i].ahat_from_tool, b[i].ahat_from_tool);
    ExpectSamePose(a[i].filtered_ahat_from_tool, b[i].filtered_ahat_from_tool);
    ExpectSamePose(a[i].world_from_tool, b[i].world_from_tool);
  }
}

TEST(ToolPosesIo, CsvRoundTripsEveryFieldExactly) {
  const std::vector<ToolPoseRecord> records = Records();
  const std::vector<ToolPoseRecord> back = DecodeToolPoses(EncodeToolPosesCsv(records));
  ExpectSame(back, records);
  EXPECT_EQ(back[0].rotation_sd_deg, 0.0);  // the pose's sds are in the JSON form only
  EXPECT_EQ(back[0].position_sd_mm, 0.0);
}

TEST(ToolPosesIo, JsonRoundTripsEveryFieldExactly) {
  const std::vector<ToolPoseRecord> records = Records();
  const std::vector<ToolPoseRecord> back = DecodeToolPoses(EncodeToolPosesJson(records));
  ExpectSame(back, records);
  EXPECT_EQ(back[0].rotation_sd_deg, records[0].rotation_sd_deg);
  EXPECT_EQ(back[0].position_sd_mm, records[0].position_sd_mm);
  EXPECT_EQ(back[0].filtered_rotation_sd_deg, records[0].filtered_rotation_sd_deg);
  // Files written before the sds existed still read (as 0).
  std::string old = EncodeToolPosesJson(records);
  for (const std::string key :
       {"\"rotation_sd_deg\"", "\"position_sd_mm\"", "\"filtered_rotation_sd_deg\""}) {
    const std::size_t at = old.find(key);
    ASSERT_NE(at, std::string::npos);
    old.erase(at, old.find('\n', at) + 1 - at);
  }
  EXPECT_EQ(DecodeToolPoses(old)[0].rotation_sd_deg, 0.0);
  EXPECT_EQ(DecodeToolPoses(old)[0].filtered_rotation_sd_deg, 0.0);
}

TEST(ToolPosesIo, StatusNamesRoundTrip) {
  for (const ToolStatus s :
       {ToolStatus::kOk, ToolStatus::kPartiallyOccluded, ToolStatus::kAmbiguous,
        ToolStatus::kTooFewMarkers, ToolStatus::kOutOfView}) {
    EXPECT_EQ(ParseToolStatus(ToString(s)), s);
  }
  EXPECT_FALSE(ParseToolStatus("lost").has_value());
}

TEST(ToolPosesIo, BestPoseIsTheFilteredOneWhenPresent) {
  std::vector<ToolPoseRecord> records = Records();
  EXPECT_EQ(records[0].best_ahat_from_tool()->translation, Eigen::Vector3d(1, 2, 3));
  records[0].filtered_ahat_from_tool.reset();
  EXPECT_EQ(records[0].best_ahat_from_tool()->translation.z(), 456.789);
}

// Decoding `text` throws an IoError whose message contains `needle` and, when given, `offset`.
void ExpectError(const std::string& text, const std::string& needle,
                 std::optional<std::uint64_t> offset = std::nullopt) {
  try {
    DecodeToolPoses(text, "poses.csv");
    ADD_FAILURE() << "no error for: " << text;
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("poses.csv"), std::string::npos) << e.what();
    if (offset) {
      EXPECT_EQ(e.offset(), offset) << e.what();
    }
  }
}

TEST(ToolPosesIo, RejectsMalformedCsvNamingTheByte) {
  const std::string csv = EncodeToolPosesCsv(Records());
  const std::size_t row = csv.find('\n') + 1;
  ExpectError("", "header");
  ExpectError("frame,tool\n", "header", 0);
  ExpectError(csv.substr(0, row) + "x" + csv.substr(row), "frame index", row);
  ExpectError(csv.substr(0, row) + "1,2\n", "columns", row);
  std::string bad_status = csv;
  bad_status.replace(bad_status.find("partially_occluded"), 18, "lost");
  ExpectError(bad_status, "unknown status");
  std::string half_pose = csv;
  const std::size_t q = half_pose.find(",1,2,3,");  // the filtered pose's translation
  half_pose.replace(q, 7, ",1,,3,");
  ExpectError(half_pose, "all 7 values");
  std::string scaled = csv;
  scaled.replace(scaled.find(",1,0,0,0,1,2,3"), 14, ",2,0,0,0,1,2,3");
  ExpectError(scaled, "unit norm");
  ExpectError(csv + "1,2,3\n", "columns");
}

TEST(ToolPosesIo, RejectsMalformedJson) {
  ExpectError("{\"format\": \"other\"}", "tofnav-tool-poses");
  ExpectError("{\"format\": \"tofnav-tool-poses\"}", "records");
  ExpectError("{\"format\": \"tofnav-tool-poses\", \"records\": [{\"frame\": 1}]}", "host_ticks");
  std::string json = EncodeToolPosesJson(Records());
  json.replace(json.find("\"frame\": 7"), 10, "\"frame\": 1e300");
  ExpectError(json, "\"frame\" must be an integer");
  ExpectError("{\"format\": \"tofnav-tool-poses\", \"records\": [", "malformed JSON");
}

}  // namespace
}  // namespace tofnav
