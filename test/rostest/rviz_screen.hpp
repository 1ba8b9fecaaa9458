// rviz on a private screen, for the rostests that look at what it draws
// (rviz_render, demo_pictures): a child process group, Xvfb on a free
// display, the config's background colour, a screenshot by ImageMagick's
// `import`, and what the 3D view holds.
#pragma once

#include <ros/ros.h>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace stc_rviz {

// The screen the shipped rviz configs fill: rviz/demo.rviz opens a 1920x1080
// window (full screen on such a screen); on a smaller one only its top-left
// part shows, and the view the tests judge is cut.
constexpr int kScreenWidth = 1920;
constexpr int kScreenHeight = 1080;
constexpr int kColourfulSpread = 40;  // max(r,g,b) - min(r,g,b) above this: "in colour"

inline std::optional<std::string> findExecutable(const std::string& name) {
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

// Starts Xvfb on a free display of kScreenWidth x kScreenHeight; returns ":N", or "" when it does not come up.
inline std::string startXvfb(Child& xvfb, const std::string& exe, const std::string& log_path) {
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
inline std::optional<std::array<int, 3>> backgroundOf(const std::string& rviz_config) {
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
inline std::optional<Screenshot> takeScreenshot(const std::string& import_exe, const std::string& display,
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
  // The 3D view: the columns of the background colour, from its top row to the
  // bottom of the screen (a view filled by the scene below shows no background there).
  int x0 = 0, y0 = 0, x1 = -1;
  long view_pixels = 0;      // pixels of the 3D view
  long coloured_pixels = 0;  // of those, in colour
  long selected_pixels = 0;  // of those, chosen by analyse's `select`
  std::size_t distinct_colours = 0;
  double colouredShare() const { return view_pixels ? double(coloured_pixels) / double(view_pixels) : 0.0; }
};

// What the 3D view (the region of the config's background colour) shows;
// `select` (optional) picks pixels by colour for selected_pixels.
using PixelTest = std::function<bool(int r, int g, int b)>;
inline ViewContent analyse(const Screenshot& shot, const std::array<int, 3>& background, const PixelTest& select = {}) {
  int x0 = shot.width, x1 = -1, y0 = shot.height;
  auto pixel = [&](int x, int y) { return &shot.rgb[(static_cast<std::size_t>(y) * shot.width + x) * 3]; };
  for (int y = 0; y < shot.height; ++y) {
    for (int x = 0; x < shot.width; ++x) {
      const unsigned char* p = pixel(x, y);
      if (p[0] == background[0] && p[1] == background[1] && p[2] == background[2]) {
        x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y);
      }
    }
  }
  ViewContent c;
  if (x1 < 0) return c;
  c.x0 = x0, c.y0 = y0, c.x1 = x1;
  std::set<std::uint32_t> colours;
  for (int y = y0; y < shot.height; ++y) {
    for (int x = x0; x <= x1; ++x) {
      const unsigned char* p = pixel(x, y);
      ++c.view_pixels;
      const int spread = std::max({p[0], p[1], p[2]}) - std::min({p[0], p[1], p[2]});
      c.coloured_pixels += spread > kColourfulSpread;
      if (select) c.selected_pixels += select(p[0], p[1], p[2]);
      colours.insert((std::uint32_t(p[0]) << 16) | (std::uint32_t(p[1]) << 8) | p[2]);
    }
  }
  c.distinct_colours = colours.size();
  return c;
}

}  // namespace stc_rviz
