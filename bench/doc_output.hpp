// A bench's report: numbers formatted for its tables, printed, and written to
// the docs file when asked.
#pragma once

#include <cstdio>
#include <fstream>
#include <string>

namespace stc::bench {

// A number for a table, printf-formatted.
inline std::string num(double v, const char* fmt = "%.2f") {
  char buf[48];
  std::snprintf(buf, sizeof buf, fmt, v);
  return buf;
}

// Prints `doc`; writes it to `path` unless empty. Returns the exit code (1: not written).
inline int printAndWrite(const std::string& doc, const std::string& path) {
  std::fputs(doc.c_str(), stdout);
  if (path.empty()) return 0;
  std::ofstream out(path);
  if (!out) {
    std::fprintf(stderr, "cannot write %s\n", path.c_str());
    return 1;
  }
  out << doc;
  return 0;
}

}  // namespace stc::bench
