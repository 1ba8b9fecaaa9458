// rviz renders the demo under Xvfb: a screenshot of the render area is not
// blank (most of it is the scene, not rviz's background colour) and holds
// several distinct colours. Skipped with a clear message where Xvfb or
// ImageMagick's `import` is not installed.
#include "child_process.hpp"
#include "rostest_util.hpp"

#include <gtest/gtest.h>
#include <visualization_msgs/MarkerArray.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <set>
#include <sys/stat.h>
#include <unistd.h>

namespace {

bool onPath(const std::string& tool) {
  return std::system(("command -v " + tool + " >/dev/null 2>&1").c_str()) == 0;
}

struct Image {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;
};

// Binary PPM (P6, maxval 255), as `import` writes it.
bool readPpm(const std::string& path, Image& image) {
  std::ifstream in(path, std::ios::binary);
  std::string magic;
  int maxval = 0;
  in >> magic >> image.width >> image.height >> maxval;
  if (!in || magic != "P6" || maxval != 255) return false;
  in.get();
  image.rgb.resize(static_cast<std::size_t>(image.width) * image.height * 3);
  in.read(reinterpret_cast<char*>(image.rgb.data()), static_cast<std::streamsize>(image.rgb.size()));
  return static_cast<bool>(in);
}

struct Coverage {
  double scene_fraction = 0.0;  // pixels of the render area not of the background colour
  std::size_t colours = 0;      // distinct colours (quantised to 32 levels per channel)
};

// The render area of the shipped configs at 1280x800 lies right of the
// Displays panel: sample x in [420, 1260), y in [80, 760).
Coverage measure(const Image& image) {
  const unsigned char background[3] = {38, 40, 46};  // rviz/demo.rviz Background Color
  std::size_t scene = 0, total = 0;
  std::set<int> colours;
  for (int y = 80; y < std::min(760, image.height); ++y) {
    for (int x = 420; x < std::min(1260, image.width); ++x) {
      const unsigned char* p = &image.rgb[(static_cast<std::size_t>(y) * image.width + x) * 3];
      const int d = std::abs(p[0] - background[0]) + std::abs(p[1] - background[1]) + std::abs(p[2] - background[2]);
      ++total;
      if (d > 24) ++scene;
      colours.insert((p[0] / 8) * 1024 + (p[1] / 8) * 32 + p[2] / 8);
    }
  }
  return {total ? static_cast<double>(scene) / total : 0.0, colours.size()};
}

TEST(Rviz, RendersTheDemo) {
  if (!onPath("Xvfb")) GTEST_SKIP() << "Xvfb is not installed: rviz rendering is not tested (apt install xvfb)";
  if (!onPath("import")) GTEST_SKIP() << "ImageMagick's import is not installed: no screenshot (apt install imagemagick)";
  std::string config;
  ASSERT_TRUE(ros::param::get("~config", config));

  // A free display number.
  int display = 90;
  struct stat st{};
  while (display < 200 && stat(("/tmp/.X11-unix/X" + std::to_string(display)).c_str(), &st) == 0) ++display;
  const std::string name = ":" + std::to_string(display);
  stc_test::Child xvfb({"Xvfb", name, "-screen", "0", "1280x800x24", "-nolisten", "tcp"}, {});
  ASSERT_TRUE(xvfb.started()) << "cannot start Xvfb: " << std::strerror(xvfb.spawnError());
  ASSERT_TRUE(stc_test::spinUntil([&] { return stat(("/tmp/.X11-unix/X" + std::to_string(display)).c_str(), &st) == 0; }, 10.0))
      << "Xvfb did not start on " << name;

  // The world publishes markers (only while someone listens: rviz will).
  ros::NodeHandle nh;
  stc_test::Recorder<visualization_msgs::MarkerArray> markers(nh, "/markers", 2);
  ASSERT_TRUE(markers.waitFor(1, 20.0)) << "no markers from the world node";

  stc_test::Child rviz({"rviz", "-d", config}, {"DISPLAY=" + name, "LIBGL_ALWAYS_SOFTWARE=1"});
  ASSERT_TRUE(rviz.started()) << "cannot start rviz: " << std::strerror(rviz.spawnError());
  const std::string shot = "/tmp/stc_rviz_test_" + std::to_string(getpid()) + ".ppm";
  Coverage best;
  // Software rendering of the first frames takes a while: retry until the scene shows.
  const bool shown = stc_test::spinUntil(
      [&] {
        stc_test::spinFor(2.0);
        if (!rviz.running()) return false;
        if (std::system(("DISPLAY=" + name + " import -window root -depth 8 " + shot + " >/dev/null 2>&1").c_str()) != 0) return false;
        Image image;
        if (!readPpm(shot, image)) return false;
        best = measure(image);
        return best.scene_fraction > 0.3 && best.colours > 20;
      },
      60.0);
  std::printf("[rviz] screenshot %s: %.0f %% of the render area is scene, %zu colours\n", shot.c_str(),
              100.0 * best.scene_fraction, best.colours);
  EXPECT_TRUE(rviz.running()) << "rviz exited";
  EXPECT_TRUE(shown) << "the render area stayed (nearly) blank: " << 100.0 * best.scene_fraction << " % scene, "
                     << best.colours << " colours";
  std::remove(shot.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rviz_test");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
