// Every JSON file the tools read names its keys: a key a reader does not know is refused, never
// skipped (a misspelt "damper" would otherwise load as an undamped model).
#pragma once

#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace vibid {

/// The name in `known` nearest to `name` (edit distance, ignoring case), or "" when none is
/// near enough to be a slip of the keyboard.
std::string NearestName(std::string_view name, std::initializer_list<std::string_view> known);
/// The same over names held in a vector (a command line's commands and options).
std::string NearestName(std::string_view name, const std::vector<std::string>& known);

/// Refuses the first key of `object` that is not in `known` with an InputError
/// "unknown key 'damper' in <what> (did you mean 'dampers'?)", or listing the valid keys when
/// none is near. `what` names the file and, for a nested object, where in it. A value that is
/// not an object is left to the reader.
void RequireKnownKeys(const nlohmann::json& object, std::initializer_list<std::string_view> known,
                      const std::string& what);

}  // namespace vibid
