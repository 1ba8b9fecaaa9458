// /diagnostics: the world node reports each concern as its own status with the
// keys documented in docs/ros_interface.md; a rejected gaze is counted under its
// topic and turns the next "rejected inputs" report into a warning.
#include "rostest_util.hpp"

#include <sphere_tree_collision/ros/tick_fields.hpp>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <gtest/gtest.h>
#include <sphere_tree_collision/GazePoint.h>

#include <map>
#include <optional>
#include <string>

namespace {

using diagnostic_msgs::DiagnosticArray;
using diagnostic_msgs::DiagnosticStatus;
using stc_test::kLivenessSeconds;
using stc_test::Recorder;
using stc_test::spinUntil;

const char* const kNode = "collision_world: ";

// The status of the world node named "<node>: <concern>" in `array`, if there.
std::optional<DiagnosticStatus> statusOf(const DiagnosticArray& array, const std::string& concern) {
  for (const DiagnosticStatus& s : array.status) {
    if (s.name == kNode + concern) return s;
  }
  return std::nullopt;
}

std::map<std::string, std::string> valuesOf(const DiagnosticStatus& status) {
  std::map<std::string, std::string> values;
  for (const auto& kv : status.values) values[kv.key] = kv.value;
  return values;
}

TEST(Diagnostics, EveryConcernReportedWithItsKeysAndRejectionsCounted) {
  ros::NodeHandle nh;
  Recorder<DiagnosticArray> diagnostics(nh, "/diagnostics", 1000);
  diagnostics.keep_all = true;
  ASSERT_TRUE(spinUntil([&] { return statusOf(diagnostics.last, "entities").has_value(); }, kLivenessSeconds))
      << "no world node status on /diagnostics";

  const std::map<std::string, std::vector<std::string>> keys{
      {"tick rate", {"ticks per second (tick stamps)", "~rate", "ticks since the last report", "tick"}},
      {"tick budget", {"ticks over budget", "ticks over budget since the last report", "budget ms", "budget from",
                       "publishing ms", "last tick ms"}},
      {"rejected inputs", {"rejected inputs", "spawn", "despawn", "gaze", "clicked_point", "last rejection"}},
      {"entities", {"entities", "~max_entities"}},
      {"quarantined bodies", {"quarantined (total)", "left the world (total)", "last removal"}}};
  for (const auto& [concern, names] : keys) {
    const auto status = statusOf(diagnostics.last, concern);
    ASSERT_TRUE(status) << "no status '" << kNode << concern << "'";
    const auto values = valuesOf(*status);
    for (const std::string& key : names) EXPECT_EQ(values.count(key), 1u) << concern << ": no key '" << key << "'";
  }
  // The tick report: every field of the one list tick_stats is filled from,
  // by its tick_stats name; flags as numbers.
  const auto report = valuesOf(*statusOf(diagnostics.last, "tick report"));
  std::size_t fields = 0;
  stc_ros::forEachReportField(sphere_tree_collision::TickStats{}, [&](const char* name, const auto&) {
    ++fields;
    EXPECT_EQ(report.count(name), 1u) << "tick report: no key '" << name << "'";
  });
  EXPECT_EQ(report.size(), fields);
  EXPECT_EQ(report.at("entities"), "6");
  EXPECT_TRUE(report.at("interrupted") == "0" || report.at("interrupted") == "1") << report.at("interrupted");
  const auto entities = valuesOf(*statusOf(diagnostics.last, "entities"));
  EXPECT_EQ(entities.at("entities"), "6");  // the default scene
  EXPECT_EQ(entities.at("~max_entities"), "50");
  EXPECT_EQ(statusOf(diagnostics.last, "entities")->level, DiagnosticStatus::OK);
  EXPECT_EQ(valuesOf(*statusOf(diagnostics.last, "tick rate")).at("~rate"), "30");
  EXPECT_EQ(valuesOf(*statusOf(diagnostics.last, "quarantined bodies")).at("quarantined (total)"), "0");
  const auto before = valuesOf(*statusOf(diagnostics.last, "rejected inputs"));
  EXPECT_EQ(before.at("rejected inputs"), "0");
  EXPECT_EQ(statusOf(diagnostics.last, "rejected inputs")->level, DiagnosticStatus::OK);

  // An off-screen gaze is rejected: the next report counts it under "gaze" and warns.
  ros::Publisher gaze = nh.advertise<sphere_tree_collision::GazePoint>("/collision_world/gaze", 1);
  ASSERT_TRUE(spinUntil([&] { return gaze.getNumSubscribers() > 0; }, kLivenessSeconds));
  sphere_tree_collision::GazePoint off_screen;
  off_screen.x = -5.0;
  off_screen.y = 10.0;
  gaze.publish(off_screen);
  std::optional<DiagnosticStatus> counted;
  ASSERT_TRUE(spinUntil(
      [&] {
        for (const DiagnosticArray& a : diagnostics.all) {
          const auto s = statusOf(a, "rejected inputs");
          if (s && valuesOf(*s).at("gaze") == "1") {
            counted = s;
            return true;
          }
        }
        return false;
      },
      kLivenessSeconds))
      << "the rejected gaze never showed on /diagnostics";
  const auto values = valuesOf(*counted);
  EXPECT_EQ(values.at("rejected inputs"), "1");
  EXPECT_EQ(values.at("spawn"), "0");
  EXPECT_NE(values.at("last rejection").find("gaze: x"), std::string::npos) << values.at("last rejection");
  EXPECT_EQ(counted->level, DiagnosticStatus::WARN);  // the first report after it
}

}  // namespace

int main(int argc, char** argv) { return stc_test::runTests(argc, argv, "diagnostics_test"); }
