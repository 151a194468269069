// Output files are written whole or not at all: the content goes to a temporary file in the same
// directory, is flushed, and is renamed over the destination. A crash or a Ctrl-C leaves either the
// old file or the new one, never a half-written one.
#pragma once

#include <string>
#include <string_view>

#include "vibid/common/text_input.hpp"

namespace vibid {

/// Writes `content` to `path` atomically. Throws InputError naming the path when the directory is
/// missing or not writable; the destination is untouched in that case.
void WriteFileAtomic(const std::string& path, std::string_view content);

/// Reads a whole file. Throws InputError naming the path when it cannot be opened or read, is a
/// directory, or is larger than `max_bytes`.
std::string ReadFileText(const std::string& path, std::uint64_t max_bytes = kMaxTextFileBytes);

}  // namespace vibid
