// The perception camera as a camera: CameraInfo published from the parameters,
// replaced from ~camera_info_topic (the gaze is then judged on the new image),
// cameras the core's pinhole cannot be refused by field, and gaze_simulator's
// image taken from the published CameraInfo.
#include "rostest_util.hpp"

#include <gtest/gtest.h>
#include <rosgraph_msgs/Log.h>
#include <sensor_msgs/CameraInfo.h>
#include <sphere_tree_collision/GazePoint.h>
#include <sphere_tree_collision/TickStats.h>

#include <algorithm>
#include <cmath>

namespace {

using sensor_msgs::CameraInfo;
using sphere_tree_collision::GazePoint;
using sphere_tree_collision::TickStats;
using stc_test::kLivenessSeconds;
using stc_test::Recorder;
using stc_test::spinUntil;

constexpr double kPi = 3.14159265358979323846;

CameraInfo pinhole(std::uint32_t width, std::uint32_t height, double f) {
  CameraInfo info;
  info.header.frame_id = "external_camera";
  info.width = width;
  info.height = height;
  info.distortion_model = "plumb_bob";
  info.D.assign(5, 0.0);
  info.K = {f, 0, 0.5 * width, 0, f, 0.5 * height, 0, 0, 1};
  info.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  info.P = {f, 0, 0.5 * width, 0, 0, f, 0.5 * height, 0, 0, 0, 1, 0};
  return info;
}

class CameraInfoTest : public ::testing::Test {
 protected:
  CameraInfoTest()
      : info_(nh_, "/collision_world/camera_info"), stats_(nh_, "/collision_world/tick_stats"), rosout_(nh_, "/rosout", 1000) {
    info_.keep_all = true;
    rosout_.keep_all = true;
    gaze_pub_ = nh_.advertise<GazePoint>("/collision_world/gaze", 10);
    external_pub_ = nh_.advertise<CameraInfo>("/external_camera/camera_info", 10, true);
  }

  void sendGaze(double x, double y) {
    ASSERT_TRUE(spinUntil([&] { return gaze_pub_.getNumSubscribers() > 0; }, kLivenessSeconds));
    GazePoint g;
    g.header.stamp = ros::Time::now();
    g.x = x;
    g.y = y;
    gaze_pub_.publish(g);
  }

  bool loggedError(const std::string& text) const {
    return std::any_of(rosout_.all.begin(), rosout_.all.end(), [&](const rosgraph_msgs::Log& log) {
      return log.level == rosgraph_msgs::Log::ERROR && log.msg.find(text) != std::string::npos;
    });
  }

  ros::NodeHandle nh_;
  Recorder<CameraInfo> info_;
  Recorder<TickStats> stats_;
  Recorder<rosgraph_msgs::Log> rosout_;
  ros::Publisher gaze_pub_, external_pub_;
};

TEST_F(CameraInfoTest, PublishedFromParametersThenTakenFromTheTopic) {
  // From the parameters: 1000 x 500, 50 degrees, principal point at the centre.
  ASSERT_TRUE(info_.waitFor(1, kLivenessSeconds)) << "no CameraInfo on /collision_world/camera_info";
  const double f = 250.0 / std::tan(25.0 * kPi / 180.0);
  EXPECT_EQ(info_.last.width, 1000u);
  EXPECT_EQ(info_.last.height, 500u);
  EXPECT_EQ(info_.last.header.frame_id, "perception_camera");
  EXPECT_NEAR(info_.last.K[0], f, 1e-9);
  EXPECT_NEAR(info_.last.K[4], f, 1e-9);
  EXPECT_DOUBLE_EQ(info_.last.K[2], 500.0);
  EXPECT_DOUBLE_EQ(info_.last.K[5], 250.0);
  EXPECT_DOUBLE_EQ(info_.last.P[0], info_.last.K[0]);
  for (double d : info_.last.D) EXPECT_EQ(d, 0.0);

  // gaze_simulator (fixed, no ~pixel) looks at the centre of that image.
  Recorder<GazePoint> simulated(nh_, "/sim/gaze");
  ASSERT_TRUE(simulated.waitFor(1, kLivenessSeconds));
  EXPECT_DOUBLE_EQ(simulated.last.x, 500.0);
  EXPECT_DOUBLE_EQ(simulated.last.y, 250.0);

  // x = 800 is on the 1000-pixel image: accepted.
  sendGaze(800.0, 100.0);
  ASSERT_TRUE(spinUntil([&] { return stats_.count() > 0 && stats_.last.gaze_active; }, kLivenessSeconds));
  EXPECT_EQ(stats_.last.rejected_gaze, 0u);

  // A 640 x 480 camera on ~camera_info_topic replaces the parameters' one.
  external_pub_.publish(pinhole(640, 480, 400.0));
  ASSERT_TRUE(spinUntil([&] { return info_.last.width == 640u; }, kLivenessSeconds)) << "camera not taken from the topic";
  EXPECT_EQ(info_.last.height, 480u);
  EXPECT_NEAR(info_.last.K[0], 400.0, 1e-9);
  EXPECT_NEAR(info_.last.K[4], 400.0, 1e-9);
  EXPECT_DOUBLE_EQ(info_.last.K[2], 320.0);
  EXPECT_EQ(info_.last.header.frame_id, "perception_camera");  // the pose and frame stay the node's

  // x = 800 is off the 640-pixel image now: rejected, naming the new width.
  sendGaze(800.0, 100.0);
  ASSERT_TRUE(spinUntil([&] { return stats_.last.rejected_gaze == 1u; }, kLivenessSeconds));
  EXPECT_NE(stats_.last.last_rejection.find("gaze: x: off screen"), std::string::npos) << stats_.last.last_rejection;
  EXPECT_NE(stats_.last.last_rejection.find("640"), std::string::npos) << stats_.last.last_rejection;

  // Cameras the core's pinhole cannot be are refused by field; the camera stays.
  CameraInfo off_centre = pinhole(800, 600, 500.0);
  off_centre.K[2] = off_centre.P[2] = 100.0;  // image_geometry projects with P (rectified)
  CameraInfo distorted = pinhole(800, 600, 500.0);
  distorted.D[0] = -0.2;
  CameraInfo not_square = pinhole(800, 600, 500.0);
  not_square.K[0] = not_square.P[0] = 520.0;
  const std::size_t infos = info_.count();
  for (const auto& [bad, expected] : {std::make_pair(off_centre, "K: the principal point"), std::make_pair(distorted, "D: "),
                                      std::make_pair(not_square, "K: pixels must be square")}) {
    const std::string text = std::string("rejected camera_info message: ") + expected;
    external_pub_.publish(bad);
    EXPECT_TRUE(spinUntil([&] { return loggedError(text); }, kLivenessSeconds)) << "no ERROR '" << text << "'";
  }
  EXPECT_EQ(info_.count(), infos) << "a refused camera was published";
  EXPECT_EQ(info_.last.width, 640u);
  const std::uint64_t tick = stats_.last.tick;
  EXPECT_TRUE(spinUntil([&] { return stats_.last.tick > tick + 3; }, kLivenessSeconds)) << "the world stopped ticking";
}

}  // namespace

int main(int argc, char** argv) { return stc_test::runTests(argc, argv, "camera_info_test"); }
