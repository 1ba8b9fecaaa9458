// Camera from tf: while the frame ~camera_frame is missing the node projects
// clicked points with the camera of its parameters (looking +y); once the
// frame appears (here at y = 5 looking -y) it uses that one. A point at
// y = 6 is in front of the first camera and behind the second.
#include "rostest_util.hpp"

#include "sphere_tree_collision/perception.hpp"
#include "sphere_tree_collision/ros/conversions.hpp"

#include <geometry_msgs/PointStamped.h>
#include <gtest/gtest.h>
#include <sphere_tree_collision/TickStats.h>
#include <tf2_ros/static_transform_broadcaster.h>

namespace {

geometry_msgs::PointStamped click(double x, double y, double z) {
  geometry_msgs::PointStamped p;
  p.header.frame_id = "world";
  p.header.stamp = ros::Time::now();
  p.point.x = x;
  p.point.y = y;
  p.point.z = z;
  return p;
}

TEST(CameraTf, ParametersUntilTheFrameExistsThenTf) {
  ros::NodeHandle nh;
  ros::Publisher clicked = nh.advertise<geometry_msgs::PointStamped>("/clicked_point", 10);
  stc_test::Recorder<sphere_tree_collision::TickStats> stats(nh, "/collision_world/tick_stats");
  ASSERT_TRUE(stc_test::spinUntil([&] { return clicked.getNumSubscribers() > 0 && stats.count() > 0; }, stc_test::kLivenessSeconds));

  // No test_camera in tf yet: the parameter camera sees the point.
  clicked.publish(click(0.0, 6.0, 0.5));
  ASSERT_TRUE(stc_test::spinUntil([&] { return stats.last.gaze_active; }, stc_test::kLivenessSeconds))
      << "last rejection: " << stats.last.last_rejection;
  EXPECT_EQ(stats.last.rejected_clicked_point, 0u);

  // The camera appears in tf, across the scene and facing back.
  tf2_ros::StaticTransformBroadcaster broadcaster;
  const stc::Pose pose = stc::opticalLookAt(stc::Vec3(0.0, 5.0, 1.0), stc::Vec3(0.0, 0.0, 1.0));
  geometry_msgs::TransformStamped t;
  t.header.stamp = ros::Time::now();
  t.header.frame_id = "world";
  t.child_frame_id = "test_camera";
  t.transform.translation = stc_ros::toVector3Msg(pose.position);
  t.transform.rotation = stc_ros::toQuaternionMsg(pose.orientation);
  broadcaster.sendTransform(t);
  // The node looks the frame up every tick; until it has it, the parameter
  // camera still sees the point. Click until the tf camera rejects it.
  ros::SteadyTimer clicker = nh.createSteadyTimer(ros::WallDuration(0.1), [&](const ros::SteadyTimerEvent&) {
    clicked.publish(click(0.0, 6.0, 0.5));
  });
  ASSERT_TRUE(stc_test::spinUntil([&] { return stats.last.rejected_clicked_point >= 1u; }, stc_test::kLivenessSeconds));
  clicker.stop();
  EXPECT_EQ(stats.last.last_rejection.rfind("clicked_point: point: behind the camera", 0), 0u)
      << stats.last.last_rejection;
  // Until the gaze of the last click the parameter camera took has expired:
  // every click still in flight is behind the tf camera and is refused, so
  // from here on only the next click can turn the gaze on.
  ASSERT_TRUE(stc_test::spinUntil([&] { return !stats.last.gaze_active; }, stc_test::kLivenessSeconds));
  // And a point in front of the tf camera is taken. The clicks before it
  // come first on the same link, so they are all counted once it shows.
  clicked.publish(click(0.0, 0.0, 1.0));
  ASSERT_TRUE(stc_test::spinUntil([&] { return stats.last.gaze_active; }, stc_test::kLivenessSeconds));
  const std::uint64_t rejected = stats.last.rejected_clicked_point;
  const std::uint64_t tick = stats.last.tick;
  ASSERT_TRUE(stc_test::spinUntil([&] { return stats.last.tick >= tick + 10; }, stc_test::kLivenessSeconds));
  EXPECT_EQ(stats.last.rejected_clicked_point, rejected) << stats.last.last_rejection;
}

}  // namespace

int main(int argc, char** argv) { return stc_test::runTests(argc, argv, "camera_tf_test"); }
