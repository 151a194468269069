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

/// An output file claimed before the work that fills it (a recording from the board): the
/// constructor creates the temporary file in the destination's directory, so a missing or
/// read-only directory, or a destination that is a directory, is refused before the work starts
/// rather than after. Commit writes the content and renames it over the destination, as
/// WriteFileAtomic does; a file never committed leaves the destination untouched and its
/// temporary file removed.
class AtomicOutputFile {
 public:
  /// Throws InputError naming `path` when it cannot be written.
  explicit AtomicOutputFile(std::string path);
  ~AtomicOutputFile();
  AtomicOutputFile(const AtomicOutputFile&) = delete;
  AtomicOutputFile& operator=(const AtomicOutputFile&) = delete;

  const std::string& path() const { return path_; }
  /// Writes `content` and renames the file into place. Once only.
  void Commit(std::string_view content);

 private:
  void Fail(const std::string& reason);

  std::string path_;
  std::string temp_path_;
  int fd_ = -1;
};

/// Reads a whole file. Throws InputError naming the path when it cannot be opened or read, is a
/// directory, or is larger than `max_bytes`.
std::string ReadFileText(const std::string& path, std::uint64_t max_bytes = kMaxTextFileBytes);

}  // namespace vibid
