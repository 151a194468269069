// Helpers shared by the CLI commands: output routing, number validators and the numerical error
// kind (input errors are vibid::InputError, device errors vibid::device::DeviceError).
#pragma once

#include <optional>
#include <stdexcept>
#include <string>

#include <CLI/CLI.hpp>

#include "exit_codes.hpp"

namespace vibid::cli {

/// A computation that ran on valid input but did not produce a usable result (the solver's
/// summary message goes into the text). Exit code kExitNumerical.
class NumericalError : public std::runtime_error {
 public:
  explicit NumericalError(const std::string& message) : std::runtime_error(message) {}
};

/// Writes `content` to `path` atomically, or to stdout when `path` is empty or "-".
void EmitOutput(const std::string& content, const std::string& path);

/// CLI11 validator: a finite number > 0.
const CLI::Validator& PositiveNumber();
/// CLI11 validator: a finite number >= 0.
const CLI::Validator& NonNegativeNumber();

}  // namespace vibid::cli
