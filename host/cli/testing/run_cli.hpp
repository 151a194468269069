// Runs the `vibid` binary in a child process for CLI tests (exit code, stdout, stderr).
#pragma once

#include <string>
#include <vector>

namespace vibid::testing {

struct CliResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

/// Runs `vibid ARGS...` (the binary built alongside the test) and waits for it.
CliResult RunVibid(const std::vector<std::string>& args);

/// A fresh empty directory under the system temp dir, unique per call.
std::string MakeTempDir(const std::string& tag);

}  // namespace vibid::testing
