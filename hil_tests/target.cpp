#include "target.hpp"

#include <algorithm>
#include <cstdlib>
#include <stdexcept>
#include <thread>

#include "emulator_process.hpp"
#include "qemu_board.hpp"
#include "vibid/device/error.hpp"
#include "vibid/device/hid_transport.hpp"
#include "vibid/device/usbip_transport.hpp"

namespace vibid::hil {
namespace {

class CoreTarget final : public Target {
 public:
  std::string Name() const override { return "core"; }
  std::unique_ptr<device::Connection> Connect(device::ConnectionOptions options) override {
    return std::make_unique<device::Connection>(loopback_.Connect(), options);
  }
  bool Restart() override {
    loopback_.Restart();
    return true;
  }
  CoreLoopback* loopback() override { return &loopback_; }
  bool Kill() override {
    loopback_.Kill();
    return true;
  }

 private:
  CoreLoopback loopback_;
};

class EmuTarget final : public Target {
 public:
  explicit EmuTarget(const std::string& binary) : emu_(binary) {}
  std::string Name() const override { return "emu"; }
  std::unique_ptr<device::Connection> Connect(device::ConnectionOptions options) override {
    return std::make_unique<device::Connection>(device::UsbipDevice::Open("127.0.0.1", emu_.port()),
                                                options);
  }
  bool Restart() override {
    emu_.Restart();
    return true;
  }
  bool Kill() override {
    emu_.Kill();
    return true;
  }
  EmulatorProcess* emulator() override { return &emu_; }

 private:
  EmulatorProcess emu_;
};

class HidTarget final : public Target {
 public:
  std::string Name() const override { return "hid"; }
  std::unique_ptr<device::Connection> Connect(device::ConnectionOptions options) override {
    return std::make_unique<device::Connection>(device::OpenHid(""), options);
  }
  bool Restart() override { return false; }
};

class QemuTarget final : public Target {
 public:
  explicit QemuTarget(const std::string& image) : board_(image) {}
  std::string Name() const override { return "qemu"; }
  std::unique_ptr<device::Connection> Connect(device::ConnectionOptions options) override {
    return std::make_unique<device::Connection>(board_.Connect(), options);
  }
  bool Restart() override { return false; }
  bool NeedsFeed() const override { return true; }
  bool Feed(device::Connection& c, std::uint32_t first, std::uint32_t frames) override {
    for (std::uint32_t k = 0; k < frames; k += wire::InjectFramesRequest::kMaxFrames) {
      wire::InjectFramesRequest r;
      r.frame_count = static_cast<std::uint8_t>(
          std::min<std::uint32_t>(wire::InjectFramesRequest::kMaxFrames, frames - k));
      for (std::uint8_t i = 0; i < r.frame_count; ++i)
        r.raw[i] = CoreLoopback::FrameAt(first + k + i);
      std::array<std::uint8_t, wire::InjectFramesRequest::kBytes> bytes{};
      wire::Encode(r, bytes);
      // A full sample queue answers unavailable: the same frames go again once it drained.
      for (;;) {
        const device::Reply reply =
            c.Call(wire::Command::kInjectFrames, std::span(bytes).first(wire::EncodedSize(r)));
        if (reply.header.status == Status::kOk) break;
        if (reply.header.status != Status::kUnavailable) {
          throw device::DeviceError(std::string("inject-frames refused: ") +
                                    StatusName(reply.header.status));
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
    }
    return true;
  }

 private:
  QemuBoard board_;
};

}  // namespace

std::string EmulatorBinary() {
  // VIBID_EMU overrides the emulator binary the build knows.
  const char* emu = std::getenv("VIBID_EMU");
#ifdef VIBID_EMU_PATH
  if (emu == nullptr || *emu == '\0') emu = VIBID_EMU_PATH;
#endif
  return emu == nullptr ? "" : emu;
}

std::unique_ptr<Target> MakeTarget() {
  const char* env = std::getenv("VIBID_TARGET");
  const std::string name = env == nullptr ? "" : env;
  const std::string emu = EmulatorBinary();
  if ((name.empty() || name == "emu") && !emu.empty()) return std::make_unique<EmuTarget>(emu);
  if (name == "emu")
    throw std::invalid_argument("VIBID_TARGET=emu needs VIBID_EMU (the vibid-emu binary)");
  if (name.empty() || name == "core") return std::make_unique<CoreTarget>();
  if (name == "hid") return std::make_unique<HidTarget>();
  if (name == "qemu") {
    const char* image = std::getenv("VIBID_QEMU_IMAGE");
    if (image == nullptr || *image == '\0') {
      throw std::invalid_argument(
          "VIBID_TARGET=qemu needs VIBID_QEMU_IMAGE (build/firmware/.../vibid_board_qemu.elf)");
    }
    return std::make_unique<QemuTarget>(image);
  }
  throw std::invalid_argument("VIBID_TARGET=" + name + ": expected emu, core, qemu or hid");
}

}  // namespace vibid::hil
