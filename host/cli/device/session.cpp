#include "session.hpp"

#include <unistd.h>

#include <csignal>
#include <cstdio>

#include "vibid/device/error.hpp"
#include "vibid/device/select.hpp"

namespace vibid::cli {
namespace {

std::atomic<bool> g_interrupted{false};  // the first Ctrl-C
std::atomic<bool> g_aborted{false};      // a second one
static_assert(std::atomic<bool>::is_always_lock_free, "set from a signal handler");

extern "C" void OnSigint(int) {
  if (g_interrupted.exchange(true)) g_aborted.store(true);
}

/// Installs the SIGINT handler for its lifetime, restoring the previous one after.
class SigintGuard {
 public:
  SigintGuard() {
    struct sigaction sa {};
    sa.sa_handler = OnSigint;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &previous_);
  }
  ~SigintGuard() { sigaction(SIGINT, &previous_, nullptr); }
  SigintGuard(const SigintGuard&) = delete;
  SigintGuard& operator=(const SigintGuard&) = delete;

 private:
  struct sigaction previous_ {};
};

}  // namespace

const std::atomic<bool>& InterruptFlag() { return g_interrupted; }

void UntilCtrlC() {
  SigintGuard guard;
  while (!g_interrupted.load()) ::usleep(100000);
}

void TakesDeviceOption(CLI::App* command) {
  // The command's own --help lists its options only: say where the board comes from.
  command->footer(
      "The board: --device hid[:SERIAL]|usbip://HOST:PORT|serial:PATH|qemu, before or after the "
      "command's name; default: the VIBID_DEVICE environment variable (the option wins over it), "
      "else the only board found.");
  for (CLI::App* a = command; a != nullptr && a->get_parent() != nullptr; a = a->get_parent())
    a->fallthrough();
}

device::DeviceSpec ChosenDevice(const GlobalOptions& globals) {
  const device::DeviceChoice choice = device::ChooseDevice(globals.device);
  return device::ParseDeviceSpec(choice.text, choice.origin);
}

void WithDevice(const GlobalOptions& globals, const std::function<void(device::Connection&)>& body,
                CtrlC ctrl_c) {
  const device::DeviceSpec spec = ChosenDevice(globals);
  SigintGuard guard;
  device::ConnectionOptions options;
  options.cancel = ctrl_c == CtrlC::kInterrupts ? &g_interrupted : &g_aborted;
  device::Connection connection(device::OpenTransport(spec), options);
  body(connection);
}

ProgressBar::ProgressBar(std::string what)
    : what_(std::move(what)), tty_(isatty(STDERR_FILENO) == 1) {}

ProgressBar::~ProgressBar() {
  if (drawn_) std::fputc('\n', stderr);
}

void ProgressBar::Update(std::uint64_t done, std::uint64_t total) {
  if (!tty_ || total == 0) return;
  const int permille = static_cast<int>(std::min<std::uint64_t>(1000, done * 1000 / total));
  if (permille == last_permille_) return;
  last_permille_ = permille;
  constexpr int kWidth = 30;
  const int filled = permille * kWidth / 1000;
  std::fprintf(stderr, "\r%s [%.*s%*s] %3d%% %llu/%llu", what_.c_str(), filled,
               "##############################", kWidth - filled, "", permille / 10,
               static_cast<unsigned long long>(done), static_cast<unsigned long long>(total));
  std::fflush(stderr);
  drawn_ = true;
}

}  // namespace vibid::cli
