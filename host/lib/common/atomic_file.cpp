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
  Require(!path.empty(), "output path is empty");
  // mkstemp in the destination's directory so the final rename never crosses file systems.
  std::string tmpl = DirectoryOf(path) + "/.vibid-tmp-XXXXXX";
  const int fd = ::mkstemp(tmpl.data());
  if (fd < 0) {
    throw InputError("cannot write '" + path + "': " + std::strerror(errno));
  }
  const char* data = content.data();
  std::size_t left = content.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, data, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      const std::string reason = std::strerror(errno);
      ::close(fd);
      ::unlink(tmpl.c_str());
      throw InputError("cannot write '" + path + "': " + reason);
    }
    data += n;
    left -= static_cast<std::size_t>(n);
  }
  // Files are created 0600 by mkstemp; give them the usual permissions for a user's output.
  ::fchmod(fd, 0644);
  if (::fsync(fd) != 0 || ::close(fd) != 0) {
    const std::string reason = std::strerror(errno);
    ::unlink(tmpl.c_str());
    throw InputError("cannot write '" + path + "': " + reason);
  }
  if (std::rename(tmpl.c_str(), path.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    ::unlink(tmpl.c_str());
    throw InputError("cannot write '" + path + "': " + reason);
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
