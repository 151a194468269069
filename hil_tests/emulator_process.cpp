#include "emulator_process.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <thread>

#include "run_cli.hpp"

namespace vibid::hil {

EmulatorProcess::EmulatorProcess(std::string binary, std::vector<std::string> extra_args)
    : binary_(std::move(binary)), extra_args_(std::move(extra_args)) {
  char tmpl[] = "/tmp/vibid-emu-XXXXXX";
  if (mkdtemp(tmpl) == nullptr) throw std::runtime_error("cannot create a temporary directory");
  dir_ = tmpl;
  Start();
}

EmulatorProcess::~EmulatorProcess() {
  Kill();
  std::error_code ec;
  std::filesystem::remove_all(dir_, ec);
}

void EmulatorProcess::Start() {
  int out[2];
  if (pipe(out) != 0) throw std::runtime_error("pipe failed");
  const std::string log = dir_ + "/emu.log";
  const int err = open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (err < 0) throw std::runtime_error("cannot create " + log);
  std::vector<std::string> args = {binary_, "--port", "0", "--flash", flash_path(), "-v"};
  args.insert(args.end(), extra_args_.begin(), extra_args_.end());
  pid_ = fork();
  if (pid_ < 0) throw std::runtime_error("fork failed");
  if (pid_ == 0) {
    dup2(out[1], STDOUT_FILENO);
    dup2(err, STDERR_FILENO);
    close(out[0]);
    close(out[1]);
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(argv[0], argv.data());
    _exit(127);
  }
  close(err);
  close(out[1]);
  // First line: "vibid-emu: USB/IP on 127.0.0.1:PORT, bus id ..."
  std::string line;
  char ch = 0;
  while (read(out[0], &ch, 1) == 1 && ch != '\n') line.push_back(ch);
  close(out[0]);
  const std::size_t at = line.find("127.0.0.1:");
  if (at == std::string::npos) {
    Kill();
    throw std::runtime_error("vibid-emu did not start: '" + line + "' " + Log());
  }
  port_ = std::atoi(line.c_str() + at + 10);
  banner_ = line;
}

std::string EmulatorProcess::device_spec() const {
  return "usbip://127.0.0.1:" + std::to_string(port_);
}

std::string EmulatorProcess::Log() const { return testing::ReadFileBytes(dir_ + "/emu.log"); }

bool EmulatorProcess::AwaitLog(const std::string& text, int count,
                               std::chrono::milliseconds timeout) const {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    const std::string log = Log();
    int seen = 0;
    for (std::size_t at = log.find(text); at != std::string::npos;
         at = log.find(text, at + text.size()))
      ++seen;
    if (seen >= count) return true;
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

void EmulatorProcess::Restart() {
  Kill();
  Start();
}

void EmulatorProcess::Kill() {
  if (pid_ > 0) {
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
    pid_ = -1;
  }
}

}  // namespace vibid::hil
