// rviz renders the demo (issue 5, rostest 5): under a private Xvfb, rviz with
// the shipped config (rviz/demo.rviz) draws the world node's markers.
//
// rviz_render.test launches the demo without rviz; this node starts Xvfb (it
// picks a free display itself, -displayfd) and rviz on it, waits for the
// node's markers, then takes screenshots (ImageMagick `import`) until the 3D
// view shows them. The 3D view is found as the region of the config's
// background colour; it is not blank when enough of its pixels are coloured
// (the grid and the background are grey; every entity is drawn in colour).
// Without Xvfb the test is skipped (gtest SKIPPED, not passed) with a message.
#include "rostest_util.hpp"
#include "rviz_screen.hpp"

#include <gtest/gtest.h>
#include <visualization_msgs/MarkerArray.h>

#include <cstdio>
#include <fstream>
#include <string>

namespace {

constexpr double kMarkersTimeout = 30.0;  // s: node start-up on a busy machine
constexpr double kRenderTimeout = 120.0;   // s: rviz start-up and first frames (software GL)
// Share of the 3D view that must be in colour. With the default scene about
// 10% is; the grid and background alone give 0.
constexpr double kMinColouredShare = 0.005;

using namespace stc_rviz;

TEST(RvizRender, DemoIsDrawn) {
  const auto xvfb_exe = findExecutable("Xvfb");
  if (!xvfb_exe) {
    GTEST_SKIP() << "Xvfb is not installed: the rviz render test is SKIPPED (apt-get install xvfb to run it)";
  }
  const auto rviz_exe = findExecutable("rviz");
  const auto import_exe = findExecutable("import");
  ASSERT_TRUE(rviz_exe) << "rviz not found on PATH (scripts/install_deps.sh installs it)";
  ASSERT_TRUE(import_exe) << "ImageMagick's import not found (package imagemagick)";
  std::string rviz_config;
  ASSERT_TRUE(ros::param::get("~rviz_config", rviz_config)) << "test parameter ~rviz_config missing";
  const auto background = backgroundOf(rviz_config);
  ASSERT_TRUE(background) << rviz_config << " has no Global Options/Background Color";

  char dir_template[] = "/tmp/stc_rviz_render_XXXXXX";
  ASSERT_NE(::mkdtemp(dir_template), nullptr);
  const std::string dir = dir_template;
  const std::string screenshot = dir + "/screenshot.ppm";

  ros::NodeHandle nh;
  stc_test::Recorder<visualization_msgs::MarkerArray> markers(nh, "/collision_world/markers", 2);
  ASSERT_TRUE(markers.waitFor(1, kMarkersTimeout)) << "the world node published no markers within " << kMarkersTimeout << " s";
  std::size_t voxel_markers = 0;
  for (const auto& m : markers.last.markers) voxel_markers += m.ns == "voxels";
  ASSERT_GT(voxel_markers, 0u) << "the demo's markers hold no entity";

  Child xvfb, rviz;
  const std::string display = startXvfb(xvfb, *xvfb_exe, dir + "/xvfb.log");
  ASSERT_FALSE(display.empty()) << "Xvfb did not start (log: " << dir << "/xvfb.log)";
  ASSERT_TRUE(rviz.start({*rviz_exe, "-d", rviz_config}, display, dir + "/rviz.log"));

  // Screenshots until the 3D view shows the markers (rviz takes a while to
  // start and to draw its first frames in software GL).
  ViewContent last;
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(kRenderTimeout);
  bool drawn = false;
  while (!drawn && ros::ok() && ros::WallTime::now() < end) {
    stc_test::spinFor(2.0);
    ASSERT_TRUE(rviz.running()) << "rviz exited (log: " << dir << "/rviz.log)";
    if (const auto shot = takeScreenshot(*import_exe, display, screenshot)) {
      last = analyse(*shot, *background);
      drawn = last.colouredShare() >= kMinColouredShare;
    }
  }
  std::printf("[rviz_render] %s on %s: 3D view %ld px, %.1f%% in colour, %zu distinct colours; screenshot %s\n",
              rviz_config.c_str(), display.c_str(), last.view_pixels, 100.0 * last.colouredShare(),
              last.distinct_colours, screenshot.c_str());
  std::fflush(stdout);
  EXPECT_GT(last.view_pixels, kScreenWidth * kScreenHeight / 10) << "no 3D view of the background colour on screen";
  EXPECT_GE(last.colouredShare(), kMinColouredShare)
      << "the 3D view stays blank (grid and background only); see " << screenshot << " and " << dir << "/rviz.log";
  EXPECT_GT(last.distinct_colours, 50u) << "a flat view: shading should give many colours";

  rviz.stop();
  xvfb.stop();
  std::string keep;  // optional: where to keep the last screenshot (PPM), e.g. for docs
  if (ros::param::get("~keep_screenshot", keep) && !keep.empty()) {
    std::ifstream in(screenshot, std::ios::binary);
    std::ofstream(keep, std::ios::binary) << in.rdbuf();
  }
  if (!::testing::Test::HasFailure()) {  // keep the screenshot and logs of a failure only
    for (const char* f : {"/screenshot.ppm", "/rviz.log", "/xvfb.log"}) std::remove((dir + f).c_str());
    ::rmdir(dir.c_str());
  }
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rviz_render_test");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
