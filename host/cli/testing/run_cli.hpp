// Runs the `vibid` binary in a child process for CLI tests (exit code, stdout, stderr), and reads
// back the files it writes.
#pragma once

#include <sys/types.h>

#include <string>
#include <vector>

namespace vibid::testing {

struct CliResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

/// `vibid ARGS...` running in the background, for tests that act on it while it runs (signals,
/// pulling the device away). The destructor kills and reaps a child that was not waited for.
class VibidProcess {
 public:
  /// `program` empty: the `vibid` built alongside the test.
  explicit VibidProcess(const std::vector<std::string>& args, const std::string& program = "");
  ~VibidProcess();
  VibidProcess(const VibidProcess&) = delete;
  VibidProcess& operator=(const VibidProcess&) = delete;

  pid_t pid() const { return pid_; }
  /// Sends `signal` to the child.
  void Signal(int signal);
  /// Collects stdout and stderr until the child closes them, then its exit code (128 + signal
  /// number when a signal ended it).
  CliResult Wait();

 private:
  pid_t pid_ = -1;
  int out_ = -1;
  int err_ = -1;
};

/// Runs `vibid ARGS...` (the binary built alongside the test) and waits for it.
CliResult RunVibid(const std::vector<std::string>& args);

/// Runs another program of the build (e.g. vibid-emu) the same way.
CliResult RunProgram(const std::string& program, const std::vector<std::string>& args);

/// A fresh empty directory under the system temp dir, unique per call.
std::string MakeTempDir(const std::string& tag);

/// The whole file, byte for byte; empty when it cannot be read (e.g. a log not written yet).
std::string ReadFileBytes(const std::string& path);

}  // namespace vibid::testing
