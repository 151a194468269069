#include "vibid/bench/bench_files.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>

#include "vibid/common/error.hpp"

namespace vibid::bench {
namespace {

/// How many `-k` names are tried before giving up (a directory full of one second's names).
constexpr int kMaxSuffix = 1000;

std::string Numbered(const std::string& stem, int k) {
  return k == 1 ? stem : stem + "-" + std::to_string(k);
}

std::string Why() { return std::strerror(errno); }

}  // namespace

std::string PrepareDirectory(const std::string& directory) {
  Require(!directory.empty(), "the bench's directory (-o) is empty");
  if (::mkdir(directory.c_str(), 0700) != 0 && errno != EEXIST)
    throw InputError("cannot create the bench's directory '" + directory + "': " + Why());
  // Resolved once, here: the board, the routes and every file after use this path, so a link
  // on the way that someone re-points later leads nowhere new.
  char* resolved = ::realpath(directory.c_str(), nullptr);
  if (resolved == nullptr) throw InputError("the bench's directory '" + directory + "': " + Why());
  const std::string path(resolved);
  std::free(resolved);
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0)
    throw InputError("the bench's directory '" + directory + "': " + Why());
  Require(S_ISDIR(st.st_mode), "the bench's directory '" + directory + "' is not a directory");
  Require(st.st_uid == ::geteuid(),
          "the bench's directory '" + directory +
              "' belongs to another user: choose one of your own (-o), whose files the page "
              "reads and writes");
  Require((st.st_mode & S_IWOTH) == 0,
          "the bench's directory '" + directory +
              "' is writable by every user, who could plant links in it: choose a private "
              "one (-o; the bench creates a missing one with mode 0700)");
  Require((st.st_mode & S_IWGRP) == 0,
          "the bench's directory '" + directory +
              "' is writable by its group, whose members could plant links in it: choose a "
              "private one (-o; the bench creates a missing one with mode 0700) or chmod g-w it");
  // The folders above it: one that another user may write into (without the sticky bit that
  // keeps others' entries, as /tmp has) or that another user owns could have the directory
  // renamed away and another put in its place.
  for (std::filesystem::path up = std::filesystem::path(path).parent_path();;
       up = up.parent_path()) {
    struct stat a {};
    if (::stat(up.c_str(), &a) != 0) throw InputError("'" + up.string() + "': " + Why());
    const bool others_write = (a.st_mode & (S_IWGRP | S_IWOTH)) != 0 && (a.st_mode & S_ISVTX) == 0;
    const bool others_own = a.st_uid != 0 && a.st_uid != ::geteuid();
    Require(!others_write && !others_own,
            "the bench's directory '" + path + "' lies in '" + up.string() + "', which " +
                (others_own ? "another user owns" : "other users may write into") +
                ": they could put another directory in its place; choose one under folders "
                "only you (or root) can change (-o)");
    if (up == up.root_path() || up.empty()) break;
  }
  return path;
}

std::string FileIn(const std::string& directory, const nlohmann::json& name,
                   const std::string& what) {
  Require(name.is_string(), "'" + what + "' must be a file name");
  const std::string s = name.get<std::string>();
  const bool control = std::any_of(
      s.begin(), s.end(), [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; });
  Require(!control, "'" + what + "': the name holds a control character (a NUL cuts a name short)");
  bool inside = !s.empty() && s.front() != '/';
  for (std::size_t start = 0; inside && start <= s.size();) {
    const std::size_t end = std::min(s.find('/', start), s.size());
    inside = end > start && s[start] != '.';
    start = end + 1;
  }
  Require(inside, "'" + what + "': '" + s +
                      "' is not a file in the bench's directory (a name, or folder/name, with no "
                      "part starting with a dot)");
  // No part may be a symbolic link: a link would lead the read or the write out of the
  // directory. The parts that do not exist yet (an output's name) are created by the bench.
  std::string path = directory;
  for (std::size_t start = 0; start <= s.size();) {
    const std::size_t end = std::min(s.find('/', start), s.size());
    path += "/" + s.substr(start, end - start);
    struct stat st {};
    if (::lstat(path.c_str(), &st) != 0) break;
    Require(!S_ISLNK(st.st_mode), "'" + what + "': '" + s +
                                      "' passes through a symbolic link; the bench follows none "
                                      "in its directory");
    start = end + 1;
  }
  return directory + "/" + s;
}

std::string OutputIn(const std::string& directory, const nlohmann::json& name,
                     const std::string& what) {
  const std::string path = FileIn(directory, name, what);
  const std::string s = name.get<std::string>();
  const bool json = s.size() > 5 && s.compare(s.size() - 5, 5, ".json") == 0;
  Require(json && s.find('/') == std::string::npos,
          "'" + what + "': '" + s +
              "' is not a name the bench writes a result to: a NAME.json in the bench's "
              "directory itself (recordings, journals and saved tests are never replaced)");
  return path;
}

NewFile CreateNewFile(const std::string& directory, const std::string& stem,
                      const std::string& suffix, const std::string& also_free) {
  for (int k = 1; k <= kMaxSuffix; ++k) {
    NewFile f;
    f.stem = Numbered(stem, k);
    f.path = directory + "/" + f.stem + suffix;
    struct stat st {};
    if (!also_free.empty() && ::lstat((directory + "/" + f.stem + also_free).c_str(), &st) == 0)
      continue;
    f.fd = ::open(f.path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
    if (f.fd >= 0) return f;
    if (errno != EEXIST) throw InputError("cannot create '" + f.path + "': " + Why());
  }
  throw InputError("cannot create a new " + stem + suffix + " in '" + directory +
                   "': " + std::to_string(kMaxSuffix) + " names taken");
}

std::string CreateNewDirectory(const std::string& directory, const std::string& stem) {
  for (int k = 1; k <= kMaxSuffix; ++k) {
    const std::string path = directory + "/" + Numbered(stem, k);
    if (::mkdir(path.c_str(), 0700) == 0) return path;
    if (errno != EEXIST) throw InputError("cannot create '" + path + "': " + Why());
  }
  throw InputError("cannot create a new folder " + stem + " in '" + directory +
                   "': " + std::to_string(kMaxSuffix) + " names taken");
}

std::string PublishNewFile(const std::string& directory, const std::string& stem,
                           const std::string& suffix, std::string_view content) {
  std::string temp = directory + "/.vibid-tmp-XXXXXX";
  const int fd = ::mkstemp(temp.data());
  if (fd < 0) throw InputError("cannot write in '" + directory + "': " + Why());
  const auto fail = [&](const std::string& why) {
    ::close(fd);
    ::unlink(temp.c_str());
    throw InputError("cannot write " + stem + suffix + " in '" + directory + "': " + why);
  };
  for (std::size_t done = 0; done < content.size();) {
    const ssize_t n = ::write(fd, content.data() + done, content.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) fail(Why());
    done += static_cast<std::size_t>(n);
  }
  ::fchmod(fd, 0644);
  if (::fsync(fd) != 0) fail(Why());
  ::close(fd);
  for (int k = 1; k <= kMaxSuffix; ++k) {
    const std::string path = directory + "/" + Numbered(stem, k) + suffix;
    if (::renameat2(AT_FDCWD, temp.c_str(), AT_FDCWD, path.c_str(), RENAME_NOREPLACE) == 0)
      return path;
    if (errno != EEXIST) {
      const std::string why = Why();
      ::unlink(temp.c_str());
      throw InputError("cannot write '" + path + "': " + why);
    }
  }
  ::unlink(temp.c_str());
  throw InputError("cannot write a new " + stem + suffix + " in '" + directory +
                   "': " + std::to_string(kMaxSuffix) + " names taken");
}

std::string TimeStamp() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char b[32];
  std::strftime(b, sizeof b, "%Y%m%dT%H%M%SZ", &tm);
  return b;
}

}  // namespace vibid::bench
