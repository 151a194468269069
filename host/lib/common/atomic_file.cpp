#include "vibid/common/atomic_file.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "vibid/common/error.hpp"
#include "vibid/common/text_input.hpp"

namespace vibid {
namespace {

std::string DirectoryOf(const std::string& path) {
  const auto slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

}  // namespace

void WriteFileAtomic(const std::string& path, std::string_view content) {
  AtomicOutputFile(path).Commit(content);
}

AtomicOutputFile::AtomicOutputFile(std::string path) : path_(std::move(path)) {
  Require(!path_.empty(), "output path is empty");
  // Refused now, not at the rename after the work: rename() cannot replace a directory.
  struct stat st {};
  if (::stat(path_.c_str(), &st) == 0 && S_ISDIR(st.st_mode))
    throw InputError("cannot write '" + path_ + "': it is a directory");
  // mkstemp in the destination's directory so the final rename never crosses file systems.
  temp_path_ = DirectoryOf(path_) + "/.vibid-tmp-XXXXXX";
  fd_ = ::mkstemp(temp_path_.data());
  if (fd_ < 0) throw InputError("cannot write '" + path_ + "': " + std::strerror(errno));
}

AtomicOutputFile::~AtomicOutputFile() {
  if (fd_ >= 0) {
    ::close(fd_);
    ::unlink(temp_path_.c_str());
  }
}

void AtomicOutputFile::Fail(const std::string& reason) {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  ::unlink(temp_path_.c_str());
  throw InputError("cannot write '" + path_ + "': " + reason);
}

void AtomicOutputFile::Commit(std::string_view content) {
  Require(fd_ >= 0, "'" + path_ + "' was already written");
  const char* data = content.data();
  std::size_t left = content.size();
  while (left > 0) {
    const ssize_t n = ::write(fd_, data, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      Fail(std::strerror(errno));
    }
    data += n;
    left -= static_cast<std::size_t>(n);
  }
  // Files are created 0600 by mkstemp; give them the usual permissions for a user's output.
  ::fchmod(fd_, 0644);
  const int fd = fd_;
  fd_ = -1;
  if (::fsync(fd) != 0) {
    const std::string reason = std::strerror(errno);
    ::close(fd);
    ::unlink(temp_path_.c_str());
    throw InputError("cannot write '" + path_ + "': " + reason);
  }
  if (::close(fd) != 0 || std::rename(temp_path_.c_str(), path_.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    ::unlink(temp_path_.c_str());
    throw InputError("cannot write '" + path_ + "': " + reason);
  }
}

std::string ReadFileText(const std::string& path, std::uint64_t max_bytes) {
  RequireReadableSize(path, max_bytes);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot open '" + path + "': " + std::strerror(errno));
  // Read in blocks so a pipe that never ends is refused at the limit instead of filling memory.
  std::string text;
  char block[1 << 16];
  while (in.read(block, sizeof(block)) || in.gcount() > 0) {
    text.append(block, static_cast<std::size_t>(in.gcount()));
    if (text.size() > max_bytes) {
      throw InputError(path + ": too large (more than the " + FormatBytes(max_bytes) +
                       " this reader takes)");
    }
  }
  if (in.bad()) throw InputError("cannot read '" + path + "': " + std::strerror(errno));
  return text;
}

}  // namespace vibid
