// Helpers shared by the CLI commands: output routing and error kinds beyond InputError.
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

/// A device that is absent, refuses, or breaks off a transfer. Exit code kExitDevice.
class DeviceError : public std::runtime_error {
 public:
  explicit DeviceError(const std::string& message) : std::runtime_error(message) {}
};

/// Writes `content` to `path` atomically, or to stdout when `path` is empty or "-".
void EmitOutput(const std::string& content, const std::string& path);

/// CLI11 validator: a finite number > 0.
const CLI::Validator& PositiveNumber();
/// CLI11 validator: a finite number >= 0.
const CLI::Validator& NonNegativeNumber();

}  // namespace vibid::cli
