#include "qemu_board.hpp"

#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "run_cli.hpp"
#include "state_wait.hpp"
#include "vibid/device/serial_transport.hpp"

namespace vibid::hil {
namespace {}  // namespace

QemuBoard::QemuBoard(const std::string& image) {
  char tmpl[] = "/tmp/vibid-qemu-XXXXXX";
  if (mkdtemp(tmpl) == nullptr) throw std::runtime_error("cannot create a temporary directory");
  dir_ = tmpl;
  socket_ = dir_ + "/usart1.sock";
  diagnostics_ = dir_ + "/usart2.log";
  // The same machine the firmware's own QEMU test boots (firmware/ports/qemu/qemu_link.py).
  std::vector<std::string> args = {"qemu-system-arm",
                                   "-M",
                                   "netduinoplus2",
                                   "-display",
                                   "none",
                                   "-monitor",
                                   "none",
                                   "-no-reboot",
                                   "-icount",
                                   "shift=0,align=off,sleep=off",
                                   "-chardev",
                                   "socket,id=link,path=" + socket_ + ",server=on,wait=off",
                                   "-serial",
                                   "chardev:link",
                                   "-serial",
                                   "file:" + diagnostics_,
                                   "-kernel",
                                   image};
  pid_ = fork();
  if (pid_ < 0) throw std::runtime_error("fork failed");
  if (pid_ == 0) {
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    execvp(argv[0], argv.data());
    _exit(127);
  }
  const auto deadline = std::chrono::steady_clock::now() + hil::kStateWait;
  while (testing::ReadFileBytes(diagnostics_).find("ready") == std::string::npos) {
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = -1;
      throw std::runtime_error("qemu-system-arm exited before the image was ready");
    }
    if (std::chrono::steady_clock::now() > deadline)
      throw std::runtime_error("waited " + std::to_string(hil::kStateWait.count()) +
                               " s for the QEMU image to report ready");
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

QemuBoard::~QemuBoard() {
  if (pid_ > 0) {
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
  std::error_code ec;
  std::filesystem::remove_all(dir_, ec);
}

std::unique_ptr<device::Transport> QemuBoard::Connect() { return device::OpenSerial(socket_); }

}  // namespace vibid::hil
