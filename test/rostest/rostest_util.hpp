// Helpers shared by the rostest gtest nodes: record a topic, spin until a
// condition holds, measure a message rate.
#pragma once

#include <gtest/gtest.h>
#include <ros/ros.h>

#include <visualization_msgs/MarkerArray.h>

#include <functional>
#include <map>
#include <string>
#include <vector>

namespace stc_test {

// Wall-clock bound of a wait that only guards against a hung node: tests
// assert stamps and states, never how soon something arrives, so this is
// generous enough for a fully loaded machine.
constexpr double kLivenessSeconds = 60.0;

// Spins the default callback queue until `done()` or `timeout_s` of wall time.
inline bool spinUntil(const std::function<bool()>& done, double timeout_s) {
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout_s);
  while (ros::ok() && ros::WallTime::now() < end) {
    ros::spinOnce();
    if (done()) return true;
    ros::WallDuration(0.002).sleep();
  }
  ros::spinOnce();
  return done();
}

inline void spinFor(double seconds) {
  spinUntil([] { return false; }, seconds);
}

// Keeps the arrival times of every message and a copy of the last one.
template <typename Msg>
class Recorder {
 public:
  Recorder(ros::NodeHandle& nh, const std::string& topic, std::uint32_t queue = 100) {
    sub_ = nh.subscribe<Msg>(topic, queue, [this](const typename Msg::ConstPtr& m) {
      last = *m;
      arrivals.push_back(ros::WallTime::now());
      if (keep_all) all.push_back(*m);
    });
  }
  std::size_t count() const { return arrivals.size(); }
  void clear() {
    arrivals.clear();
    all.clear();
  }
  // Messages per second between the first and the last arrival.
  double rate() const {
    if (arrivals.size() < 2) return 0.0;
    return (arrivals.size() - 1) / (arrivals.back() - arrivals.front()).toSec();
  }
  bool waitFor(std::size_t n, double timeout_s) {
    return spinUntil([&] { return count() >= n; }, timeout_s);
  }

  Msg last;
  std::vector<ros::WallTime> arrivals;
  bool keep_all = false;
  std::vector<Msg> all;
  ros::Subscriber sub_;
};

// What rviz would hold after the marker arrays received so far: DELETEALL
// empties it, DELETE removes one (ns, id), ADD sets one.
class MarkerState {
 public:
  MarkerState(ros::NodeHandle& nh, const std::string& topic) {
    sub_ = nh.subscribe<visualization_msgs::MarkerArray>(topic, 1000, [this](const auto& a) {
      ++arrays;
      if (first.markers.empty() && arrays == 1) first = *a;
      for (const auto& m : a->markers) {
        if (m.action == visualization_msgs::Marker::DELETEALL) markers.clear();
        if (m.action == visualization_msgs::Marker::DELETE) markers.erase({m.ns, m.id});
        if (m.action == visualization_msgs::Marker::ADD) markers[{m.ns, m.id}] = m;
      }
    });
  }
  int count(const std::string& ns) const {
    int n = 0;
    for (const auto& [key, m] : markers) n += key.first == ns ? 1 : 0;
    return n;
  }

  std::map<std::pair<std::string, int>, visualization_msgs::Marker> markers;
  visualization_msgs::MarkerArray first;  // the first array received (a snapshot)
  std::size_t arrays = 0;
  ros::Subscriber sub_;
};

// Sorted "type" of an advertised topic, "" when not advertised.
inline std::string topicType(const std::string& topic) {
  ros::master::V_TopicInfo topics;
  ros::master::getTopics(topics);
  for (const auto& t : topics) {
    if (t.name == topic) return t.datatype;
  }
  return "";
}

// main() of a rostest gtest node.
inline int runTests(int argc, char** argv, const char* node_name) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, node_name);
  ros::NodeHandle nh;  // keeps ROS up while the tests run
  return RUN_ALL_TESTS();
}

}  // namespace stc_test
