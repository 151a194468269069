// Reference data of the host's tests, read from the source tree (VIBID_SOURCE_DIR, which
// vibid_add_host_test defines) so that a test runs from any working directory.
#pragma once

#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "vibid/common/json_file.hpp"

namespace vibid {

/// The JSON file at `relative_path` below the project root (e.g. a scipy reference that
/// scripts/golden/ wrote), parsed the first time a test of the process asks for it.
inline const nlohmann::json& ReadGolden(const std::string& relative_path) {
  static std::map<std::string, nlohmann::json> read;
  auto it = read.find(relative_path);
  if (it == read.end()) {
    it = read.emplace(relative_path,
                      ReadJsonFile(std::string(VIBID_SOURCE_DIR) + "/" + relative_path))
             .first;
  }
  return it->second;
}

}  // namespace vibid
