// SPDX-License-Identifier: BSD-3-Clause
// Tool JSON round trip and rejection of malformed files; NDI .rom marker import.
#include "tofnav/casefile/tool_json.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "tofnav/io/io_error.hpp"

namespace tofnav {
namespace {

ToolGeometry Tool() {
  ToolGeometry tool;
  tool.name = "HeadRef";
  tool.markers_in_tool = {{-20, -45, 35}, {0, 50, 30}, {60, -55, 15}, {-30, 10, 15.25}};
  tool.marker_type = MarkerType::kSphere;
  tool.marker_diameter_mm = 12.7;
  tool.min_visible = 4;
  tool.max_fre_mm = 0.8;
  tool.tip_in_tool = Eigen::Vector3d(1.5, -2.0, 180.0);
  return tool;
}

TEST(ToolJson, RoundTripsEveryField) {
  const ToolGeometry tool = Tool();
  const ToolGeometry back = DecodeToolJson(EncodeToolJson(tool));
  EXPECT_EQ(back.name, tool.name);
  ASSERT_EQ(back.markers_in_tool.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(back.markers_in_tool[i], tool.markers_in_tool[i]);
  EXPECT_EQ(back.marker_type, MarkerType::kSphere);
  EXPECT_EQ(back.marker_diameter_mm, 12.7);
  EXPECT_EQ(back.min_visible, 4);
  EXPECT_EQ(back.max_fre_mm, 0.8);
  ASSERT_TRUE(back.tip_in_tool.has_value());
  EXPECT_EQ(*back.tip_in_tool, *tool.tip_in_tool);
}

TEST(ToolJson, AcceptsTheDocumentedAliasesAndDefaults) {
  const ToolGeometry t = DecodeToolJson(
      R"({"name": "t", "id": 3, "markers": [[0,0,0],[50,0,0],[0,60,0]],
          "marker_type": "flat", "marker_diameter": 10})");
  EXPECT_EQ(t.marker_type, MarkerType::kDisc);
  EXPECT_EQ(t.marker_diameter_mm, 10.0);
  EXPECT_EQ(t.min_visible, 3);
  EXPECT_FALSE(t.tip_in_tool.has_value());
}

TEST(ToolJson, RejectsMalformedDocumentsWithAnIoError) {
  const char* bad[] = {
      "",                                                              // empty
      "{\"name\": \"t\", \"markers\": [[0,0,0],[50,0,0],[0,60,0]]",    // truncated
      "[1, 2]",                                                        // not an object
      R"({"markers": [[0,0,0],[50,0,0],[0,60,0]]})",                   // no name
      R"({"name": "t", "markers": [[0,0,0],[50,0,0]]})",               // 2 markers
      R"({"name": "t", "markers": [[0,0,0],[0,0,1],[0,60,0]]})",       // duplicate markers
      R"({"name": "t", "markers": [[0,0],[50,0,0],[0,60,0]]})",        // 2 coordinates
      R"({"name": "t", "markers": [[0,0,"x"],[50,0,0],[0,60,0]]})",    // a string
      R"({"name": "t", "markers": [[1e999,0,0],[50,0,0],[0,60,0]]})",  // overflows a double
      R"({"name": "t", "markers": [[0,0,0],[50,0,0],[0,60,0]], "marker_type": "cube"})",
      R"({"name": "t", "markers": [[0,0,0],[50,0,0],[0,60,0]], "min_visible": 2.5})",
  };
  for (const char* text : bad) EXPECT_THROW(DecodeToolJson(text, "bad.json"), IoError) << text;
  try {
    DecodeToolJson("{\"name\": \"t\",, }", "syntax.json");
    FAIL();
  } catch (const IoError& e) {
    EXPECT_EQ(e.path(), "syntax.json");
    ASSERT_TRUE(e.offset().has_value());
    EXPECT_EQ(*e.offset(), 13u);  // the second comma
  }
}

std::vector<std::uint8_t> Rom(const std::vector<Eigen::Vector3f>& markers) {
  std::vector<std::uint8_t> bytes(72 + 12 * markers.size(), 0);
  bytes[28] = static_cast<std::uint8_t>(markers.size());
  for (std::size_t i = 0; i < markers.size(); ++i) {
    std::memcpy(&bytes[72 + 12 * i], markers[i].data(), 12);  // little-endian host
  }
  return bytes;
}

TEST(NdiRom, ReadsTheMarkerPositionsAndRejectsShortFiles) {
  const std::vector<std::uint8_t> rom = Rom({{0, 0, 0}, {0, 50, 0}, {-25, 100, 0}, {25, 135, 0}});
  const ToolGeometry tool = DecodeNdiRom(rom, "8700339.rom");
  EXPECT_EQ(tool.name, "8700339");
  ASSERT_EQ(tool.markers_in_tool.size(), 4u);
  EXPECT_EQ(tool.markers_in_tool[3], Eigen::Vector3d(25, 135, 0));
  EXPECT_EQ(tool.marker_diameter_mm, 11.5);
  std::vector<std::uint8_t> truncated(rom.begin(), rom.end() - 1);
  EXPECT_THROW(DecodeNdiRom(truncated, "t.rom"), IoError);
  EXPECT_THROW(DecodeNdiRom(std::vector<std::uint8_t>(20, 0), "t.rom"), IoError);
  EXPECT_THROW(DecodeNdiRom(Rom({{0, 0, 0}, {0, 50, 0}}), "two.rom"), IoError);
}

}  // namespace
}  // namespace tofnav
