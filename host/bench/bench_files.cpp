#include "vibid/bench/bench_files.hpp"

#include <algorithm>
#include <ctime>

#include "vibid/common/error.hpp"

namespace vibid::bench {

std::string FileIn(const std::string& directory, const nlohmann::json& name,
                   const std::string& what) {
  Require(name.is_string(), "'" + what + "' must be a file name");
  const std::string s = name.get<std::string>();
  bool inside = !s.empty() && s.front() != '/';
  for (std::size_t start = 0; inside && start <= s.size();) {
    const std::size_t end = std::min(s.find('/', start), s.size());
    inside = end > start && s[start] != '.';
    start = end + 1;
  }
  Require(inside, "'" + what + "': '" + s +
                      "' is not a file in the bench's directory (a name, or folder/name, with no "
                      "part starting with a dot)");
  return directory + "/" + s;
}

std::string TimeStamp() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char b[32];
  std::strftime(b, sizeof b, "%Y%m%dT%H%M%SZ", &tm);
  return b;
}

}  // namespace vibid::bench
