#include "session.hpp"

#include <unistd.h>

#include <csignal>
#include <cstdio>

#include "vibid/device/error.hpp"
#include "vibid/device/select.hpp"

namespace vibid::cli {
namespace {

std::atomic<bool> g_interrupted{false};

extern "C" void OnSigint(int) { g_interrupted.store(true); }

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

void WithDevice(const GlobalOptions& globals,
                const std::function<void(device::Connection&)>& body) {
  const device::DeviceSpec spec = device::ParseDeviceSpec(globals.device);
  SigintGuard guard;
  device::ConnectionOptions options;
  options.cancel = &g_interrupted;
  device::Connection connection(device::OpenTransport(spec), options);
  body(connection);
}

wire::CalibrationRecord ActiveRecord(device::Connection& c, bool& has_record) {
  wire::CalibrationRecord r;
  has_record = false;
  if (c.info().cal_state != wire::CalState::kCalibrated) return r;
  const std::vector<std::uint8_t> bytes = c.CalGet();
  if (wire::DecodeCalibrationRecord(bytes, r) != Status::kOk) {
    throw device::DeviceError("the board's active calibration record does not decode");
  }
  has_record = true;
  return r;
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
