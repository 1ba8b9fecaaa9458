// A fresh directory under /tmp for files a test writes, removed with them.
#pragma once

#include <string>
#include <vector>

namespace stc::truth {

class TempDir {
 public:
  TempDir();   // throws std::runtime_error when it cannot be made
  ~TempDir();  // removes the files named through file(), then the directory
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::string& path() const { return path_; }
  // Path of `name` in the directory, remembered for removal.
  std::string file(const std::string& name);

 private:
  std::string path_;
  std::vector<std::string> files_;
};

}  // namespace stc::truth
