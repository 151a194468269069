// Cell-level pieces of the CSV reader shared by the fast row parser (csv_parse.cpp) and the rest of
// csv.cpp. Not installed: internal to vibid_common.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace vibid::csv_detail {

/// Strips spaces, tabs and carriage returns at both ends.
std::string_view Trim(std::string_view s);

/// A whole cell as a number: optional '+', then std::from_chars must consume every character.
std::optional<double> ParseNumber(std::string_view cell);

/// Checks a header line (trimmed) and appends its names; `where` ("file:line: ") prefixes every
/// message. InputError on an empty name, a number in place of a name, or a duplicate name.
void CheckHeader(std::string_view line, const std::string& where, std::vector<std::string>& names);

/// Throws the InputError that says why a data line (trimmed) is not a row of `names.size()` cells
/// with a finite number in every kept cell (`keep` empty: every cell), naming the column by
/// 1-based index and name. Used for a line the fast parser refused.
[[noreturn]] void ExplainBadRow(std::string_view line, const std::string& where,
                                const std::vector<std::string>& names,
                                const std::vector<bool>& keep);

/// Transparent huge pages for a large buffer about to be written (Linux; no effect elsewhere or
/// when refused): the page-aligned interior of [data, data + bytes) is advised.
void AdviseHugePages(void* data, std::size_t bytes);

}  // namespace vibid::csv_detail
