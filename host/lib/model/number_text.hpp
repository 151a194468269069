// Numbers in messages, written as a user would type them (shortest round-trip form: 0.001, -1).
#pragma once

#include <charconv>
#include <string>

namespace vibid::model::detail {

inline std::string NumberText(double value) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, value);
  return ec == std::errc() ? std::string(buf, end) : std::to_string(value);
}

}  // namespace vibid::model::detail
