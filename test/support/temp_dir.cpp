#include "temp_dir.hpp"

#include <cstdio>
#include <cstdlib>
#include <stdexcept>

namespace stc::truth {

TempDir::TempDir() {
  char pattern[] = "/tmp/stc_test_XXXXXX";
  if (mkdtemp(pattern) == nullptr) throw std::runtime_error("cannot make a directory under /tmp");
  path_ = pattern;
}

TempDir::~TempDir() {
  for (const std::string& f : files_) std::remove(f.c_str());
  std::remove(path_.c_str());
}

std::string TempDir::file(const std::string& name) {
  files_.push_back(path_ + "/" + name);
  return files_.back();
}

}  // namespace stc::truth
