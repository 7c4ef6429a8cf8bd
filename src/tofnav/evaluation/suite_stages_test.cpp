// SPDX-License-Identifier: BSD-3-Clause
// The suite's stage selection (`tofnav evaluate suite --stages`): prerequisites and acceptance.
#include <gtest/gtest.h>

#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "tofnav/evaluation/demo_stages.hpp"
#include "tofnav/evaluation/suite_case.hpp"

namespace tofnav {
namespace {

std::set<std::string> With(std::vector<std::string> wanted) {
  return DemoStagesWithPrerequisites(wanted);
}

TEST(DemoStagesWithPrerequisites, TrackingNeedsTheMarkerStageAndTheSessionOnly) {
  EXPECT_EQ(With({"tracking"}), (std::set<std::string>{"marker_error", "session", "tracking"}));
  EXPECT_EQ(With({"reconstruction"}),
            (std::set<std::string>{"marker_error", "session", "depth", "reconstruction"}));
}

TEST(DemoStagesWithPrerequisites, GuidanceNeedsEveryStage) {
  const std::vector<std::string> names = DemoStageNames();
  EXPECT_EQ(With({"guidance"}), std::set<std::string>(names.begin(), names.end()));
  EXPECT_TRUE(With({}).empty());  // empty: the driver runs every stage
}

TEST(DemoStagesWithPrerequisites, AnUnknownStageIsNamedWithTheKnownOnes) {
  try {
    With({"tracking", "trackign"});
    FAIL() << "an unknown stage was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(),
                 "unknown stage 'trackign' (stages: marker_error, session, depth, reconstruction, "
                 "registration, tracking, guidance)");
  }
}

TEST(SuiteAcceptance, ARowOfSomeStagesHasTheirLinesOnly) {
  SuiteJson row{{"tracking_mm", 0.25}, {"tracking_deg", 0.40}};
  row["stages_run"] = With({"tracking"});
  const SuiteJson lines = SuiteAcceptance(row);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_TRUE(lines[0]["met"].get<bool>());
  EXPECT_FALSE(lines[1]["met"].get<bool>());  // 0.40 deg against the 0.35 deg line
  // Without "stages_run" every line is there, and a figure that is missing is not met.
  row.erase("stages_run");
  const SuiteJson all = SuiteAcceptance(row);
  EXPECT_EQ(all.size(), 7u);  // 6 figures and the registration (not accepted: no TRE line)
  EXPECT_FALSE(all[2]["met"].get<bool>());  // reconstruction_mm missing
}

}  // namespace
}  // namespace tofnav
