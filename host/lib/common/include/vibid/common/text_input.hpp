// Checks on text that comes from outside (other labs' files, other tools): how large a file a
// reader takes, whether it is UTF-8, and how to quote a piece of it in a one-line message.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace vibid {

/// Largest file ReadFileText reads whole (UFF58 files with many FRFs run to hundreds of MB).
inline constexpr std::uint64_t kMaxTextFileBytes = std::uint64_t{1} << 30;
/// Largest JSON file (models, designs, sensors, modes): a parsed JSON takes several times its size.
inline constexpr std::uint64_t kMaxJsonFileBytes = std::uint64_t{64} << 20;
/// Largest recording CSV: its columns as doubles take about 0.6 of the text, beside the mapping.
inline constexpr std::uint64_t kMaxCsvFileBytes = std::uint64_t{4} << 30;

/// Refuses a file larger than `max_bytes` (InputError naming the path, its size and the limit) and
/// anything that is not a regular file or a pipe (a directory, a device).
void RequireReadableSize(const std::string& path, std::uint64_t max_bytes);

/// Throws InputError "SOURCE:LINE:COLUMN: not UTF-8 text (byte 0xNN)" at the first byte that is
/// not part of well-formed UTF-8 (or is NUL, which marks a binary file), or "SOURCE: UTF-16 text;
/// save it as UTF-8" for a UTF-16 file.
void RequireUtf8(std::string_view text, const std::string& source);

/// The text with control characters and bytes outside printable ASCII written as \xNN, cut to
/// `max_chars` with "...": safe to quote in a one-line message on a terminal.
std::string Printable(std::string_view text, std::size_t max_chars = 40);

/// "1.50 GiB", "12.0 MiB", "512 B".
std::string FormatBytes(std::uint64_t bytes);

}  // namespace vibid
