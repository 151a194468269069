// Helpers shared by the CLI commands: output routing, number validators and the numerical error
// kind (input errors are vibid::InputError, device errors vibid::device::DeviceError).
#pragma once

#include "vibid/common/error.hpp"

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <CLI/CLI.hpp>

#include "exit_codes.hpp"
#include "vibid/common/atomic_file.hpp"

namespace vibid::cli {

/// A computation that ran on valid input but did not produce a usable result: the library's
/// (exit code kExitNumerical).
using vibid::NumericalError;

/// Writes `content` to `path` atomically, or to stdout when `path` is empty or "-".
void EmitOutput(const std::string& content, const std::string& path);

/// An output named before long work (a recording from the board): stdout for "" or "-", else
/// the file is claimed at construction (AtomicOutputFile), so a path that cannot be written is
/// refused before the work starts. Write once, at the end.
class ClaimedOutput {
 public:
  explicit ClaimedOutput(const std::string& path);
  void Write(std::string_view content);
  bool to_stdout() const { return file_ == nullptr; }
  /// The path, or "stdout".
  std::string Name() const;

 private:
  std::unique_ptr<AtomicOutputFile> file_;
};

/// The command stopped on Ctrl-C after keeping what it had and saying so on stderr: main exits
/// with kExitInterrupted and prints nothing more.
class StoppedByInterrupt : public std::exception {
 public:
  const char* what() const noexcept override { return "stopped by Ctrl-C"; }
};

/// The command wrote its result with cautions it printed beside it (friction named, estimates
/// that disagree, residual tests that fail): one `vibid: caution:` line on stderr names `what`
/// and their count. A caution is no refusal, so the command still exits 0, as an
/// identification whose verdict is a caution does (common/verdict.hpp).
void SayCautions(const std::vector<std::string>& cautions, const std::string& what);

/// For a command line CLI11 refused: the first command or option it does not know, named with
/// the nearest known one ("unknown option '--second' for 'vibid acquire' (did you mean
/// '--seconds'?)"), or "" when every word is known (CLI11's own message says then what is wrong).
/// `args` are the words after the program's name.
std::string UnknownWordMessage(const CLI::App& app, const std::vector<std::string>& args);

/// CLI11 validator: a finite number > 0.
const CLI::Validator& PositiveNumber();
/// CLI11 validator: a finite number >= 0.
const CLI::Validator& NonNegativeNumber();

}  // namespace vibid::cli
