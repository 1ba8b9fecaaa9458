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

#include <gtest/gtest.h>
#include <visualization_msgs/MarkerArray.h>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

constexpr int kScreenWidth = 1280;
constexpr int kScreenHeight = 800;
constexpr double kMarkersTimeout = 30.0;  // s: node start-up on a busy machine
constexpr double kRenderTimeout = 45.0;   // s: rviz start-up and first frames (software GL)
// Share of the 3D view that must be in colour. With the default scene about
// 10% is; the grid and background alone give 0.
constexpr double kMinColouredShare = 0.005;
constexpr int kColourfulSpread = 40;  // max(r,g,b) - min(r,g,b) above this: "in colour"

std::optional<std::string> findExecutable(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    const std::string candidate = dir + "/" + name;
    if (::access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return std::nullopt;
}

// A child process, stopped (SIGTERM, then SIGKILL) when this goes out of scope.
class Child {
 public:
  Child() = default;
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  ~Child() { stop(); }

  // argv[0] is the executable path. `display`: DISPLAY for the child ("" keeps
  // the environment's). `keep_fd`: a descriptor the child keeps (else -1).
  // Output goes to `log_path`.
  bool start(const std::vector<std::string>& argv, const std::string& display, const std::string& log_path,
             int keep_fd = -1) {
    pid_ = ::fork();
    if (pid_ < 0) return false;
    if (pid_ == 0) {
      ::setpgid(0, 0);  // own process group: stop() reaches rviz's helpers too
      const int log = ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
      if (log >= 0) {
        ::dup2(log, STDOUT_FILENO);
        ::dup2(log, STDERR_FILENO);
      }
      for (int fd = 3; fd < 1024; ++fd) {
        if (fd != keep_fd) ::close(fd);
      }
      if (!display.empty()) ::setenv("DISPLAY", display.c_str(), 1);
      std::vector<char*> args;
      for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
      args.push_back(nullptr);
      ::execv(args[0], args.data());
      std::_Exit(127);
    }
    return true;
  }
  bool running() const { return pid_ > 0 && ::waitpid(pid_, nullptr, WNOHANG) == 0; }
  void stop() {
    if (pid_ <= 0) return;
    ::kill(-pid_, SIGTERM);
    for (int i = 0; i < 50 && ::waitpid(pid_, nullptr, WNOHANG) == 0; ++i) ::usleep(100000);
    ::kill(-pid_, SIGKILL);
    ::waitpid(pid_, nullptr, 0);
    pid_ = -1;
  }

 private:
  pid_t pid_ = -1;
};

// Starts Xvfb on a free display; returns ":N", or "" when it does not come up.
std::string startXvfb(Child& xvfb, const std::string& exe, const std::string& log_path) {
  int fds[2];
  if (::pipe(fds) != 0) return "";
  const std::string size = std::to_string(kScreenWidth) + "x" + std::to_string(kScreenHeight) + "x24";
  const bool started = xvfb.start({exe, "-displayfd", std::to_string(fds[1]), "-screen", "0", size, "-nolisten", "tcp"},
                                  "", log_path, fds[1]);
  ::close(fds[1]);
  std::string number;
  pollfd p{fds[0], POLLIN, 0};
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(15.0);
  while (started && ros::WallTime::now() < end && number.find('\n') == std::string::npos) {
    if (::poll(&p, 1, 200) <= 0) continue;
    char buf[16];
    const ssize_t n = ::read(fds[0], buf, sizeof buf);
    if (n <= 0) break;
    number.append(buf, static_cast<std::size_t>(n));
  }
  ::close(fds[0]);
  const auto newline = number.find('\n');
  return newline == std::string::npos ? "" : ":" + number.substr(0, newline);
}

// "Background Color: 38; 40; 46" of an rviz config.
std::optional<std::array<int, 3>> backgroundOf(const std::string& rviz_config) {
  std::ifstream in(rviz_config);
  std::string line;
  while (std::getline(in, line)) {
    const auto at = line.find("Background Color:");
    if (at == std::string::npos) continue;
    std::array<int, 3> rgb{};
    if (std::sscanf(line.c_str() + at, "Background Color: %d; %d; %d", &rgb[0], &rgb[1], &rgb[2]) == 3) return rgb;
  }
  return std::nullopt;
}

struct Screenshot {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;  // width * height * 3, row by row
};

// The whole screen of `display`, saved by ImageMagick's `import` as a binary
// PPM (P6) at `ppm_path` and read back.
std::optional<Screenshot> takeScreenshot(const std::string& import_exe, const std::string& display,
                                         const std::string& ppm_path) {
  const std::string grab =
      import_exe + " -display " + display + " -window root -depth 8 ppm:" + ppm_path + " >/dev/null 2>&1";
  if (std::system(grab.c_str()) != 0) return std::nullopt;
  std::ifstream in(ppm_path, std::ios::binary);
  std::string magic;
  int maxval = 0;
  Screenshot shot;
  in >> magic >> shot.width >> shot.height >> maxval;
  if (!in || magic != "P6" || maxval != 255 || shot.width <= 0 || shot.height <= 0) return std::nullopt;
  in.get();  // the single whitespace before the pixels
  shot.rgb.resize(static_cast<std::size_t>(shot.width) * shot.height * 3);
  in.read(reinterpret_cast<char*>(shot.rgb.data()), static_cast<std::streamsize>(shot.rgb.size()));
  if (!in) return std::nullopt;
  return shot;
}

struct ViewContent {
  long view_pixels = 0;      // pixels of the 3D view (bounding box of the background colour)
  long coloured_pixels = 0;  // of those, in colour
  std::size_t distinct_colours = 0;
  double colouredShare() const { return view_pixels ? double(coloured_pixels) / double(view_pixels) : 0.0; }
};

ViewContent analyse(const Screenshot& shot, const std::array<int, 3>& background) {
  int x0 = shot.width, x1 = -1, y0 = shot.height, y1 = -1;
  auto pixel = [&](int x, int y) { return &shot.rgb[(static_cast<std::size_t>(y) * shot.width + x) * 3]; };
  for (int y = 0; y < shot.height; ++y) {
    for (int x = 0; x < shot.width; ++x) {
      const unsigned char* p = pixel(x, y);
      if (p[0] == background[0] && p[1] == background[1] && p[2] == background[2]) {
        x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
      }
    }
  }
  ViewContent c;
  if (x1 < 0) return c;
  std::set<std::uint32_t> colours;
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      const unsigned char* p = pixel(x, y);
      ++c.view_pixels;
      const int spread = std::max({p[0], p[1], p[2]}) - std::min({p[0], p[1], p[2]});
      c.coloured_pixels += spread > kColourfulSpread;
      colours.insert((std::uint32_t(p[0]) << 16) | (std::uint32_t(p[1]) << 8) | p[2]);
    }
  }
  c.distinct_colours = colours.size();
  return c;
}

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
