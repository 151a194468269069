// Files in the bench's directory: the directory itself (private, the user's own), the names
// requests may give (never a path out of it, never through a symbolic link) and the recordings
// and saved tests the bench creates (new names that cannot collide, created exclusively: no
// existing file or link is ever written through or over).
#pragma once

#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace vibid::bench {

/// Creates `directory` (mode 0700) when it is missing. Refuses (InputError) one that is not a
/// directory, belongs to another user, or its group or other users may write into (links could
/// be planted in it), and one under a folder another user owns or may write into without the
/// sticky bit (the directory could be swapped). Returns its resolved path, which every user of
/// the directory must take from here (BenchBoard::directory()): resolved once, a link on the way
/// re-pointed later changes nothing.
std::string PrepareDirectory(const std::string& directory);

/// `name` as a file inside `directory` (a saved test's folder may be named: "hammer-.../
/// recording.csv"), or an InputError naming `what`: no absolute path, no part that is empty or
/// starts with a dot (so no ".."), no control character (a NUL would cut the name short), and
/// no part of it that exists as a symbolic link.
std::string FileIn(const std::string& directory, const nlohmann::json& name,
                   const std::string& what);

/// A result the bench writes under a name the request gives (a design, an identified chain):
/// FileIn's checks, and a NAME.json in the directory itself, so that a recording (.csv), a
/// journal (.partial.csv, .jsonl) or a saved test's file (in its folder) is never replaced.
std::string OutputIn(const std::string& directory, const nlohmann::json& name,
                     const std::string& what);

/// A file the bench creates: `stem` + `suffix` in `directory`, or `stem-2` + `suffix`, `stem-3`
/// ... when that name is taken, created with O_EXCL | O_NOFOLLOW (mode 0600), so that neither an
/// existing file nor a planted link is used. Names whose `also_free` sibling (the same stem with
/// that suffix) exists are skipped too. Throws InputError when none can be created.
struct NewFile {
  std::string stem;  ///< The stem chosen ("bench-20261126T163423Z-2").
  std::string path;
  int fd = -1;  ///< Open for writing; the caller closes it.
};
NewFile CreateNewFile(const std::string& directory, const std::string& stem,
                      const std::string& suffix, const std::string& also_free = "");

/// A new directory `stem`, `stem-2`, ... in `directory` (mkdir refuses any existing name, a link
/// included), mode 0700. Returns its path.
std::string CreateNewDirectory(const std::string& directory, const std::string& stem);

/// Writes `content` as a new file `stem` + `suffix` in `directory` (or `stem-2` ... when taken),
/// whole or not at all: a temporary file, then renamed into place only where no name exists
/// (renameat2 RENAME_NOREPLACE). Returns the path written.
std::string PublishNewFile(const std::string& directory, const std::string& stem,
                           const std::string& suffix, std::string_view content);

/// Now in UTC as 20261126T163423Z.
std::string TimeStamp();

}  // namespace vibid::bench
