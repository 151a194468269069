// JSON files read and written by the CLI (models, designs, modal results).
#pragma once

#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace vibid {

/// Parses a JSON file; InputError naming the file, line and column on a syntax error.
nlohmann::json ReadJsonFile(const std::string& path);

/// Parses JSON text as ReadJsonFile does; `source` names it in the InputError (with the line of a
/// syntax error; a number too large for a double is an error too).
nlohmann::json ParseJsonText(std::string_view text, const std::string& source);

/// Writes `value` pretty-printed (2-space indent) and atomically.
void WriteJsonFile(const std::string& path, const nlohmann::json& value);

}  // namespace vibid
