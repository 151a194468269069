// Test support for the identification commands' CLI tests: their committed records and the
// lines and numbers of their text output.
#pragma once

#include <cmath>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

namespace vibid::testing {

/// A record of host/cli/ident/testdata (made by the scripts under scripts/golden/).
inline std::string TestData(const std::string& name) {
  return std::string(VIBID_SOURCE_DIR) + "/host/cli/ident/testdata/" + name;
}

/// The lines of `text` that contain `containing`.
inline std::vector<std::string> Lines(const std::string& text, const std::string& containing) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (line.find(containing) != std::string::npos) out.push_back(line);
  return out;
}

/// The number after `after` in `line` (NaN when absent).
inline double NumberAfter(const std::string& line, const std::string& after) {
  const auto at = line.find(after);
  if (at == std::string::npos) return std::nan("");
  return std::strtod(line.c_str() + at + after.size(), nullptr);
}

}  // namespace vibid::testing
