// Exit codes of the `vibid` CLI, in one table (scripts and the hil tests rely on them).
#pragma once

namespace vibid::cli {

enum ExitCode : int {
  kExitOk = 0,
  kExitInputError = 1,  ///< A file or value the user gave is wrong (message names it).
  kExitUsage = 2,       ///< The command line itself is wrong (unknown option, missing argument).
  kExitNumerical =
      3,  ///< The input was fine but the computation failed (no convergence, unstable filter).
  kExitDevice = 4,    ///< No device, a transfer failed, or the device refused a request.
  kExitInternal = 5,  ///< A defect: an unexpected exception.
  /// The result was written with cautions (printed with it): usable only knowing what they say.
  kExitCaution = 6,
  /// Stopped by Ctrl-C (128 + SIGINT, as the shell reports a process SIGINT ended); an
  /// acquisition stopped so keeps what it recorded and says where.
  kExitInterrupted = 130,
};

}  // namespace vibid::cli
