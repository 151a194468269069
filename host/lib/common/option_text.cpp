#include "vibid/common/option_text.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "vibid/common/csv.hpp"

namespace vibid {

std::string OptionNumber(double value) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", value);
  return b;
}

NumberText ParseNumber(std::string_view text, double& value) {
  const std::string s(text);  // strtod needs the terminating NUL
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(s.c_str(), &end);
  if (end == s.c_str() || errno == ERANGE) return NumberText::kNotANumber;
  value = v;
  if (end != s.c_str() + s.size() || !std::isfinite(v)) return NumberText::kNotFinite;
  return NumberText::kOk;
}

std::optional<long long> ParseInteger(std::string_view text, int base) {
  const std::string s(text);
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(s.c_str(), &end, base);
  if (s.empty() || end != s.c_str() + s.size() || errno == ERANGE) return std::nullopt;
  return v;
}

std::vector<std::string> SplitOptionList(std::string_view text, TrailingEmpty trailing) {
  std::vector<std::string> items = SplitList(text);
  if (trailing == TrailingEmpty::kDrop && items.back().empty()) items.pop_back();
  return items;
}

}  // namespace vibid
