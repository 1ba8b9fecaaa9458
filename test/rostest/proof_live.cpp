// The proof, live (issue 11 items 4, 5; proof_live.test): what the node shows
// and writes of each tick's error agrees with what the tick reported. Every
// comparison pairs messages by stamp (one tick), never by arrival.
#include "rostest_util.hpp"

#include <sphere_tree_collision/ContactArray.h>
#include <sphere_tree_collision/GazePoint.h>
#include <sphere_tree_collision/TickStats.h>

#include <sphere_tree_collision/ros/error_report.hpp>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <map>
#include <set>
#include <utility>
#include <vector>

namespace {

using sphere_tree_collision::ContactArray;
using sphere_tree_collision::TickStats;
using visualization_msgs::Marker;
using visualization_msgs::MarkerArray;

constexpr std::size_t kArraysChecked = 5;  // error_bounds arrays with bounds, each against its tick
constexpr std::size_t kRowsChecked = 30;   // ~error_report rows, each against its tick's tick_stats

// Messages of one topic by stamp.
template <typename Msg>
class ByStamp {
 public:
  ByStamp(ros::NodeHandle& nh, const std::string& topic) {
    sub_ = nh.subscribe<Msg>(topic, 1000, [this](const typename Msg::ConstPtr& m) { all[stampOf(*m)] = *m; });
  }
  const Msg* at(const ros::Time& stamp) const {
    const auto it = all.find(stamp);
    return it == all.end() ? nullptr : &it->second;
  }
  std::map<ros::Time, Msg> all;

 private:
  static ros::Time stampOf(const MarkerArray& a) { return a.markers.empty() ? ros::Time() : a.markers.front().header.stamp; }
  template <typename M>
  static ros::Time stampOf(const M& m) { return m.header.stamp; }
  ros::Subscriber sub_;
};

// Gap bounds of the distinct accepted unresolved pairs of a tick's contacts, sorted.
std::vector<double> unresolvedPairBounds(const ContactArray& contacts) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, double> pairs;
  for (const auto& c : contacts.contacts) {
    if (!c.resolved) pairs[{c.entity_a, c.entity_b}] = c.gap_bound;
  }
  std::vector<double> bounds;
  for (const auto& [pair, bound] : pairs) bounds.push_back(bound);
  std::sort(bounds.begin(), bounds.end());
  return bounds;
}

class ProofLive : public ::testing::Test {
 protected:
  ProofLive()
      : gaze_pub_(nh_.advertise<sphere_tree_collision::GazePoint>("/collision_world/gaze", 10)),
        stats_(nh_, "/collision_world/tick_stats"),
        contacts_(nh_, "/collision_world/contacts"),
        bounds_(nh_, "/collision_world/error_bounds"),
        markers_(nh_, "/collision_world/markers") {
    // The gaze at the image centre, kept fresh: P and the text's place follow it.
    gaze_timer_ = nh_.createSteadyTimer(ros::WallDuration(0.1), [this](const ros::SteadyTimerEvent&) {
      sphere_tree_collision::GazePoint g;
      g.x = 640.0;
      g.y = 360.0;
      gaze_pub_.publish(g);
    });
  }

  // error_bounds arrays with at least one bound whose tick's stats, contacts
  // and markers have arrived.
  std::vector<ros::Time> completeTicks() const {
    std::vector<ros::Time> ticks;
    for (const auto& [stamp, array] : bounds_.all) {
      const TickStats* s = stats_.at(stamp);
      const bool has_bound = std::any_of(array.markers.begin(), array.markers.end(), [](const Marker& m) {
        return m.ns == "error_bounds" && m.action == Marker::ADD;
      });
      if (has_bound && s && s->gaze_active && contacts_.at(stamp) && markers_.at(stamp)) ticks.push_back(stamp);
    }
    return ticks;
  }

  ros::NodeHandle nh_;
  ros::Publisher gaze_pub_;
  ros::SteadyTimer gaze_timer_;
  ByStamp<TickStats> stats_;
  ByStamp<ContactArray> contacts_;
  ByStamp<MarkerArray> bounds_, markers_;
};

TEST_F(ProofLive, BoundMarkersAreTheContactsBoundsAndTheTextTheTicksFigures) {
  ASSERT_TRUE(stc_test::spinUntil([&] { return completeTicks().size() >= kArraysChecked; }, stc_test::kLivenessSeconds))
      << "fewer than " << kArraysChecked << " error_bounds arrays with bounds matched a tick (" << bounds_.all.size()
      << " arrays)";
  std::map<int, Marker> drawn;  // what rviz holds of error_bounds, array after array
  std::size_t checked = 0, spheres = 0, kept = 0;
  for (const auto& [stamp, array] : bounds_.all) {
    SCOPED_TRACE("stamp " + std::to_string(stamp.toSec()));
    std::vector<double> radii;
    const Marker* text = nullptr;
    for (const Marker& m : array.markers) {
      EXPECT_EQ(m.header.stamp, stamp) << "one array, one tick";
      if (m.ns == "error_text") text = &m;
      if (m.ns != "error_bounds") continue;
      if (m.action == Marker::DELETE) {
        drawn.erase(m.id);
        continue;
      }
      drawn[m.id] = m;
      EXPECT_EQ(m.type, Marker::SPHERE);
      EXPECT_EQ(m.scale.x, m.scale.y);
      EXPECT_EQ(m.scale.x, m.scale.z);
      EXPECT_LT(m.color.a, 1.0) << "translucent: the contact inside shows";
      EXPECT_LT(m.color.g, 0.8) << "not the green of resolved contacts";
      radii.push_back(0.5 * m.scale.x);
    }
    std::sort(radii.begin(), radii.end());
    EXPECT_EQ(drawn.size(), radii.size()) << "bounds of earlier ticks are deleted";
    ASSERT_NE(text, nullptr) << "no error_text marker";
    EXPECT_EQ(text->type, Marker::TEXT_VIEW_FACING);

    const TickStats* s = stats_.at(stamp);
    const ContactArray* contacts = contacts_.at(stamp);
    if (!s || !contacts) continue;  // the tick's messages were not all received
    // One sphere per accepted unresolved pair, of radius h_a + h_b.
    EXPECT_EQ(radii, unresolvedPairBounds(*contacts));
    EXPECT_EQ(radii.size(), s->unresolved_accepted);
    ++checked;
    spheres += radii.size();
    kept += s->frontier_kept;  // pairs whose contacts came from a deeper frontier of an earlier tick
    double sum = 0.0;
    for (double r : radii) sum += r;
    EXPECT_NEAR(sum, s->geometric_bound, 1e-9 * std::max(1.0, s->geometric_bound)) << "the spheres add up to the bound sum";

    double nabla = -1.0, bound = -1.0, p = -1.0;
    unsigned long accepted = 0, pairs = 0;
    ASSERT_EQ(std::sscanf(text->text.c_str(),
                          "%lu of %lu pairs accepted unresolved\nbound sum (h_a+h_b) %lf m\nnabla %lf m P %lf",
                          &accepted, &pairs, &bound, &nabla, &p), 5)
        << "text: " << text->text;
    EXPECT_NEAR(nabla, s->geometric_inaccuracy, 0.0005);
    EXPECT_NEAR(bound, s->geometric_bound, 0.0005);
    EXPECT_NEAR(p, s->perceived_inaccuracy, 0.0005);
    EXPECT_EQ(accepted, s->unresolved_accepted);
    EXPECT_EQ(pairs, s->broad_pairs);

    // The text floats above the gaze point of the same tick, between it and
    // the camera (which looks from -y: the text is nearer in y).
    const MarkerArray* markers = markers_.at(stamp);
    if (!markers || !s->gaze_active) continue;
    for (const Marker& m : markers->markers) {
      if (m.ns != "gaze" || m.action != Marker::ADD) continue;
      EXPECT_NEAR(text->pose.position.x, m.pose.position.x, 1.5);
      EXPECT_LT(text->pose.position.y, m.pose.position.y);
      EXPECT_GT(text->pose.position.z, m.pose.position.z);
    }
  }
  std::printf("[proof_live] %zu arrays checked against their tick, %zu bound spheres, %zu of them kept from a deeper frontier\n",
              checked, spheres, kept);
  EXPECT_GE(checked, kArraysChecked);
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream in(line);
  std::string cell;
  while (std::getline(in, cell, ',')) cells.push_back(cell);
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

TEST_F(ProofLive, ErrorReportHasARowPerTickWithTheTicksFigures) {
  std::string path;
  ASSERT_TRUE(ros::param::get("~report", path));
  ASSERT_TRUE(stc_test::spinUntil([&] { return stats_.all.size() >= kRowsChecked + 5; }, stc_test::kLivenessSeconds));
  // Rows are line-buffered: every tick_stats received has its row (the row is
  // written right after tick_stats is published; spin on a little past).
  stc_test::spinUntil([] { return false; }, 0.5);
  std::ifstream in(path);
  ASSERT_TRUE(in) << "no report at " << path;
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(line, stc_ros::ErrorReport::header());
  const std::vector<std::string> names = split(line);
  const std::size_t columns = names.size();
  const auto column = [&](const char* name) {
    const auto at = std::find(names.begin(), names.end(), name);
    EXPECT_NE(at, names.end()) << "no column " << name;
    return static_cast<std::size_t>(at - names.begin());
  };
  const std::size_t budget_ms = column("budget_ms"), budget_tests = column("budget_sphere_tests"),
                    scheduler = column("scheduler"), broad_pairs = column("broad_pairs"),
                    unresolved = column("unresolved"), accepted = column("unresolved_accepted"),
                    nabla = column("geometric_inaccuracy"), bound = column("geometric_bound"),
                    perceived = column("perceived_inaccuracy"), narrow_ms = column("narrow_ms"),
                    sphere_tests = column("sphere_tests"), gaze_x = column("gaze_x"), gaze_y = column("gaze_y");
  ASSERT_EQ(gaze_y, columns - 1);
  std::size_t rows = 0, matched = 0, with_gaze = 0;
  unsigned long long previous_tick = 0;
  while (std::getline(in, line)) {
    if (in.eof()) break;  // a row being written: no newline yet
    const auto c = split(line);
    ASSERT_EQ(c.size(), columns) << line;
    ++rows;
    const unsigned long long tick = std::stoull(c[1]);
    EXPECT_EQ(tick, previous_tick + 1) << "a row per tick, in order";
    previous_tick = tick;
    const auto dot = c[0].find('.');
    ASSERT_NE(dot, std::string::npos) << c[0];
    const ros::Time stamp(static_cast<std::uint32_t>(std::stoul(c[0].substr(0, dot))),
                          static_cast<std::uint32_t>(std::stoul(c[0].substr(dot + 1))));
    const TickStats* s = stats_.at(stamp);
    if (!s) continue;  // before the test subscribed
    ++matched;
    SCOPED_TRACE(line);
    EXPECT_EQ(tick, s->tick);
    EXPECT_EQ(std::stod(c[budget_ms]), s->budget_ms);
    EXPECT_EQ(std::stoll(c[budget_tests]), s->budget_sphere_tests);
    EXPECT_EQ(c[scheduler], s->scheduler);
    EXPECT_EQ(std::stoul(c[broad_pairs]), s->broad_pairs);
    EXPECT_EQ(std::stoul(c[unresolved]), s->unresolved);
    EXPECT_EQ(std::stoul(c[accepted]), s->unresolved_accepted);
    EXPECT_EQ(std::stod(c[nabla]), s->geometric_inaccuracy);  // %.17g reads back exactly
    EXPECT_EQ(std::stod(c[bound]), s->geometric_bound);
    EXPECT_EQ(std::stod(c[perceived]), s->perceived_inaccuracy);
    EXPECT_EQ(std::stod(c[narrow_ms]), s->narrow_ms);
    EXPECT_EQ(std::stoll(c[sphere_tests]), s->sphere_tests);
    EXPECT_EQ(c[gaze_x].empty(), !s->gaze_active) << "gaze x, y empty exactly when no gaze is set";
    if (s->gaze_active) {
      ++with_gaze;
      EXPECT_EQ(std::stod(c[gaze_x]), 640.0);
      EXPECT_EQ(std::stod(c[gaze_y]), 360.0);
    }
  }
  std::printf("[proof_live] %zu report rows, %zu matched with tick_stats (%zu with gaze)\n", rows, matched, with_gaze);
  EXPECT_GE(matched, kRowsChecked);
  EXPECT_GT(with_gaze, 0u);
  if (!::testing::Test::HasFailure()) std::remove(path.c_str());  // kept to look at when the test fails
}

}  // namespace

int main(int argc, char** argv) { return stc_test::runTests(argc, argv, "proof_live_test"); }
