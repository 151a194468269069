// JSON files read and written by the CLI (models, designs, modal results).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace vibid {

/// Parses a JSON file; InputError naming the file, line and column on a syntax error.
nlohmann::json ReadJsonFile(const std::string& path);

/// Writes `value` pretty-printed (2-space indent) and atomically.
void WriteJsonFile(const std::string& path, const nlohmann::json& value);

}  // namespace vibid
