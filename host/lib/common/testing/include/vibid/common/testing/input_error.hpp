// What a test sees of refused input: the one-line message the CLI would print.
#pragma once

#include <string>
#include <utility>

#include "vibid/common/error.hpp"

namespace vibid {

/// The message of the InputError `f()` throws; `accepted` when it throws none.
template <typename F>
std::string InputErrorOf(F&& f, const std::string& accepted = "") {
  try {
    std::forward<F>(f)();
  } catch (const InputError& e) {
    return e.what();
  }
  return accepted;
}

}  // namespace vibid
