// Errors at the boundary between a user and the host library.
//
// Bad user input (a missing file, a malformed cell, an impossible option) is an InputError: the CLI
// catches it, prints its message on one line and exits nonzero. Numerical trouble inside a solver
// is not an exception; it is reported in the solver's Summary.
#pragma once

#include <stdexcept>
#include <string>

namespace vibid {

class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

/// A computation that ran on valid input but did not produce a usable result (the solver's
/// summary message goes into the text). The CLI exits with kExitNumerical.
class NumericalError : public std::runtime_error {
 public:
  explicit NumericalError(const std::string& message) : std::runtime_error(message) {}
};

/// Throws InputError(message) when `condition` is false. For validating options up front.
inline void Require(bool condition, const std::string& message) {
  if (!condition) throw InputError(message);
}

}  // namespace vibid
