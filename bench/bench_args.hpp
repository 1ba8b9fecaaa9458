// Command-line flags of the benchmarks: `--name value` pairs and bare switches,
// walked in order, so each bench lists only its own flags.
#pragma once

#include "sphere_tree_collision/types.hpp"

#include <cstdio>
#include <exception>
#include <string>

namespace stc_bench {

class Args {
 public:
  Args(int argc, char** argv) : argc_(argc), argv_(argv) {}
  bool more() const { return next_ < argc_; }
  const std::string& flag() { return flag_ = argv_[next_++]; }
  // The value after the current flag ("" when the flag ends the line).
  std::string value() { return next_ < argc_ ? argv_[next_++] : ""; }
  // The value after the current flag; throws InputError naming it when the line ends.
  std::string required() {
    const std::string v = value();
    if (v.empty()) throw stc::InputError(flag_, "needs a value");
    return v;
  }
  // Says which flag is unknown; the exit code for main.
  int unknown() const {
    std::fprintf(stderr, "unknown argument %s\n", flag_.c_str());
    return 2;
  }

 private:
  int argc_;
  char** argv_;
  int next_ = 1;
  std::string flag_;
};

// A bench's flags parsed by `parse(argc, argv)` into `out`; a bad flag
// (InputError or a number that does not read) is printed as "<bench>: <why>"
// and false returned: main then exits with 2.
template <typename Options, typename Parse>
bool parseFlags(const char* bench, Parse parse, int argc, char** argv, Options& out) {
  try {
    out = parse(argc, argv);
    return true;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", bench, e.what());
    return false;
  }
}

}  // namespace stc_bench
