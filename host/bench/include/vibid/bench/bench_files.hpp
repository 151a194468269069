// Files in the bench's directory: the names requests may give (never a path out of it) and the
// UTC time stamp that names each recording and saved test.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace vibid::bench {

/// `name` as a file inside `directory` (a saved test's folder may be named: "hammer-.../
/// recording.csv"), or an InputError naming `what`: no absolute path, no part that is empty or
/// starts with a dot (so no "..").
std::string FileIn(const std::string& directory, const nlohmann::json& name,
                   const std::string& what);

/// Now in UTC as 20261126T163423Z.
std::string TimeStamp();

}  // namespace vibid::bench
