// What every reader fuzzer checks: a reader either returns what it accepts or refuses with an
// InputError (the CLI prints its message on one line and exits 1). Any other exception would
// reach the user as an internal error; a crash, a hang or an unbounded allocation is caught by
// libFuzzer itself (-timeout, -rss_limit_mb, -malloc_limit_mb).
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <string>
#include <string_view>

#include "vibid/common/error.hpp"

namespace vibid::fuzz {

[[noreturn]] inline void Fail() { __builtin_trap(); }

// Not inlined, so a crash's stack names the line of the check that failed.
[[gnu::noinline]] inline void Require(bool condition) {
  if (!condition) Fail();
}

/// Runs `read`; true if it returned, false if it refused with a message. Traps on any other
/// exception and on an empty or multi-line message.
template <typename F>
bool Accepts(F&& read) {
  try {
    read();
    return true;
  } catch (const InputError& e) {
    const std::string_view message = e.what();
    Require(!message.empty() && message.find('\n') == std::string_view::npos);
    return false;
  } catch (...) {
    Fail();
  }
}

/// Equal bit for bit, or both NaN (a NaN's payload does not survive text).
inline bool Same(double a, double b) {
  if (std::isnan(a) && std::isnan(b)) return true;
  return std::memcmp(&a, &b, sizeof a) == 0;
}

}  // namespace vibid::fuzz
