#include "emulator_process.hpp"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <vector>

namespace vibid::hil {

EmulatorProcess::EmulatorProcess(std::string binary) : binary_(std::move(binary)) {
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
  std::vector<std::string> args = {binary_, "--port", "0", "--flash", dir_ + "/flash.bin"};
  pid_ = fork();
  if (pid_ < 0) throw std::runtime_error("fork failed");
  if (pid_ == 0) {
    dup2(out[1], STDOUT_FILENO);
    close(out[0]);
    close(out[1]);
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(argv[0], argv.data());
    _exit(127);
  }
  close(out[1]);
  // First line: "vibid-emu: USB/IP on 127.0.0.1:PORT, bus id ..."
  std::string line;
  char ch = 0;
  while (read(out[0], &ch, 1) == 1 && ch != '\n') line.push_back(ch);
  close(out[0]);
  const std::size_t at = line.find("127.0.0.1:");
  if (at == std::string::npos) {
    Kill();
    throw std::runtime_error("vibid-emu did not start: '" + line + "'");
  }
  port_ = std::atoi(line.c_str() + at + 10);
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
