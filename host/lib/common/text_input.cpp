#include "vibid/common/text_input.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>

#include <sys/stat.h>

#include "vibid/common/error.hpp"

namespace vibid {

std::string FormatBytes(std::uint64_t bytes) {
  char text[32];
  const auto value = static_cast<double>(bytes);
  if (bytes >= (std::uint64_t{1} << 30)) {
    std::snprintf(text, sizeof(text), "%.2f GiB", value / 1073741824.0);
  } else if (bytes >= (std::uint64_t{1} << 20)) {
    std::snprintf(text, sizeof(text), "%.1f MiB", value / 1048576.0);
  } else if (bytes >= (std::uint64_t{1} << 10)) {
    std::snprintf(text, sizeof(text), "%.1f KiB", value / 1024.0);
  } else {
    std::snprintf(text, sizeof(text), "%llu B", static_cast<unsigned long long>(bytes));
  }
  return text;
}

void RequireReadableSize(const std::string& path, std::uint64_t max_bytes) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0)
    throw InputError("cannot open '" + path + "': " + std::strerror(errno));
  if (S_ISDIR(st.st_mode)) throw InputError("cannot read '" + path + "': it is a directory");
  // Pipes and character devices (/dev/stdin) have no size to check; their readers stop at the
  // limit.
  if (!S_ISREG(st.st_mode)) return;
  const auto size = static_cast<std::uint64_t>(st.st_size);
  if (size > max_bytes) {
    throw InputError(path + ": too large (" + FormatBytes(size) + "; this reader takes at most " +
                     FormatBytes(max_bytes) + ")");
  }
}

void RequireUtf8(std::string_view text, const std::string& source) {
  if (text.size() >= 2 &&
      ((text[0] == '\xFF' && text[1] == '\xFE') || (text[0] == '\xFE' && text[1] == '\xFF'))) {
    throw InputError(source + ": UTF-16 text; save it as UTF-8");
  }
  const auto* s = reinterpret_cast<const unsigned char*>(text.data());
  const std::size_t n = text.size();
  std::size_t line = 1;
  std::size_t line_start = 0;
  for (std::size_t i = 0; i < n;) {
    const unsigned char c = s[i];
    // NUL is ASCII but no text file has one: it marks a binary file (or a sparse, zero-filled one).
    if (c < 0x80 && c != 0) {
      if (c == '\n') {
        ++line;
        line_start = i + 1;
      }
      ++i;
      continue;
    }
    // Well-formed sequences per RFC 3629: no overlong forms, no surrogates, nothing past U+10FFFF.
    std::size_t len = 0;  // stays 0 for NUL, a continuation byte or an invalid lead byte
    unsigned char lo = 0x80, hi = 0xBF;
    if (c >= 0xC2 && c <= 0xDF) {
      len = 2;
    } else if (c >= 0xE0 && c <= 0xEF) {
      len = 3;
      if (c == 0xE0) lo = 0xA0;
      if (c == 0xED) hi = 0x9F;
    } else if (c >= 0xF0 && c <= 0xF4) {
      len = 4;
      if (c == 0xF0) lo = 0x90;
      if (c == 0xF4) hi = 0x8F;
    }
    bool ok = len != 0 && i + len <= n;
    for (std::size_t k = 1; ok && k < len; ++k) {
      const unsigned char b = s[i + k];
      ok = k == 1 ? (b >= lo && b <= hi) : (b >= 0x80 && b <= 0xBF);
    }
    if (!ok) {
      char what[64];
      std::snprintf(what, sizeof(what), ":%zu:%zu: not UTF-8 text (byte 0x%02X)", line,
                    i - line_start + 1, static_cast<unsigned>(c));
      throw InputError(source + what);
    }
    i += len;
  }
}

std::string Printable(std::string_view text, std::size_t max_chars) {
  std::string out;
  for (const char ch : text) {
    if (out.size() >= max_chars) {
      out += "...";
      break;
    }
    const auto c = static_cast<unsigned char>(ch);
    if (c >= 0x20 && c < 0x7F) {
      out += ch;
    } else {
      char hex[8];
      std::snprintf(hex, sizeof(hex), "\\x%02X", static_cast<unsigned>(c));
      out += hex;
    }
  }
  return out;
}

}  // namespace vibid
