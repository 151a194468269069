#include "emulator.hpp"

#include <cstdio>
#include <thread>

#include "emu_dcd.hpp"
#include "emu_port.hpp"
#include "usb_app_device.hpp"
#include "vibid/fw/core.hpp"
#include "vibid/fw/usb/descriptors.hpp"
#include "vibid/fw/usb/device.hpp"
#include "vibid/fw/usb/dfu_runtime.hpp"
#include "vibid/fw/usb/hid_class.hpp"

namespace vibid::emu {
namespace {

using Clock = std::chrono::steady_clock;

/// Frames between two looks at the sockets while running flat out: short enough for a host
/// polling status, long enough that I/O costs little per frame.
constexpr int kChunkFrames = 10;
constexpr std::uint64_t kFrameUs = kBoardProfile.frame_us();
/// How long a reset or DFU entry waits for the host to collect its answer.
constexpr auto kRequestGrace = std::chrono::milliseconds(250);

class DetachToDfu final : public fw::usb::DfuDetachHandler {
 public:
  explicit DetachToDfu(fw::SystemControl& system) : system_(system) {}
  void OnDetach(std::uint16_t) override { system_.EnterDfu(); }

 private:
  fw::SystemControl& system_;
};

}  // namespace

// The application as the board runs it (compare firmware/ports/stm32f405/main.cpp).
struct Emulator::Application {
  Application(Emulator& emu, wire::ResetCause cause)
      : system(cause, emu.rig_, emu.options_.rig.brown_out),
        frames(emu.rig_),
        slots(emu.flash_),
        scenario(emu.rig_, frames),
        detach(system),
        dfu(detach),
        drivers{&hid, &dfu},
        strings(fw::usb::MakeDaqStrings(emu.serial_.c_str())),
        usb(dcd, drivers, fw::usb::DaqDescriptors(strings)),
        core(fw::Port{clock, frames, slots, system}, hid, emu.log_, &scenario),
        exported(usb, dcd, emu.Record()) {
    (void)core.Boot();
    (void)usb.Start();
  }

  SimClock clock;
  EmuSystemControl system;
  RigFrameSource frames;
  FlashCalibrationSlots slots;
  ScenarioCommands scenario;
  fw::usb::HidClass hid;
  DetachToDfu detach;
  fw::usb::DfuRuntime dfu;
  std::array<fw::usb::ClassDriver*, 2> drivers;
  fw::usb::DaqStrings strings;
  EmuDcd dcd;
  fw::usb::UsbDevice usb;
  fw::Core core;
  UsbAppDevice exported;
  std::uint32_t bus_resets = 0;
  Request request = Request::kNone;
};

Emulator::Emulator(EmulatorOptions options)
    : options_(std::move(options)),
      flash_(options_.flash_path),
      rig_(options_.rig, options_.seed),
      server_(options_.bind_address, options_.port, options_.verbose),
      log_(options_.log_bytes) {
  char serial[24];
  std::snprintf(serial, sizeof serial, "EMU%016llX",
                static_cast<unsigned long long>(options_.seed));
  serial_ = serial;
  last_wall_ = Clock::now();
  BootApplication(wire::ResetCause::kPowerOn);
}

Emulator::~Emulator() { server_.SetDevice(nullptr); }

usbip::UsbDevice Emulator::Record() const {
  usbip::UsbDevice d;
  d.path = "/sys/devices/platform/vibid-emu/usb1/1-1";
  d.busid = UsbIpServer::kBusId;
  d.busnum = 1;
  d.devnum = 2;
  d.speed = usbip::Speed::kFull;
  d.id_vendor = fw::usb::kVendorId;
  d.id_product = fw::usb::kProductId;
  d.bcd_device = fw::usb::kDeviceRelease;
  d.num_configurations = 1;
  d.num_interfaces = fw::usb::kInterfaceCount;
  d.interfaces = {usbip::UsbInterface{0x03, 0x00, 0x00}, usbip::UsbInterface{0xFE, 0x01, 0x01}};
  return d;
}

void Emulator::BootApplication(wire::ResetCause cause) {
  server_.SetDevice(nullptr);
  bootloader_.reset();
  app_.reset();
  app_ = std::make_unique<Application>(*this, cause);
  app_->exported.StampInTransactions(last_in_report_us_);
  server_.SetDevice(&app_->exported);
  was_sampling_ = false;
  boot_us_ = sim_us_;
  if (options_.verbose) std::fprintf(stderr, "vibid-emu: application running\n");
}

void Emulator::EnterBootloader() {
  server_.SetDevice(nullptr);
  app_.reset();
  bootloader_ = std::make_unique<DfuSeBootloader>(flash_, Record(), serial_);
  server_.SetDevice(bootloader_.get());
  if (options_.verbose) std::fprintf(stderr, "vibid-emu: DfuSe bootloader running\n");
}

void Emulator::RunFirmware() {
  if (!app_) return;
  Application& a = *app_;
  // A few main-loop passes per step: a request answered here frees the IN endpoint for the
  // next report of a stream without waiting for another socket poll.
  for (int pass = 0; pass < 4; ++pass) {
    a.usb.Task();
    if (a.usb.counters().bus_resets != a.bus_resets) {
      a.bus_resets = a.usb.counters().bus_resets;
      a.core.OnLinkReset();
    }
    a.core.Poll();
    a.exported.Service();
  }
}

bool Emulator::Busy() const {
  return app_ && (app_->frames.Running() || app_->exported.NeedsFrame());
}

bool Emulator::WaitForHost(Clock::time_point now) {
  if (!app_ || !app_->exported.WaitingForInUrb()) {
    waiting_ = false;
    return false;
  }
  if (!waiting_) {
    waiting_ = true;
    waiting_since_ = now;
  }
  return now - waiting_since_ < kHostGone;
}

void Emulator::RunFrame() {
  const std::uint64_t frame_end = sim_us_ + kFrameUs;
  if (app_) {
    Application& a = *app_;
    // The sampling interrupt: every tick of this frame, the first one at the frame's start.
    if (a.frames.Running() && !was_sampling_) {
      next_tick_us_ = sim_us_;
      sampling_start_us_.store(next_tick_us_, std::memory_order_release);
    }
    while (a.frames.Running() && next_tick_us_ < frame_end) {
      a.clock.Set(next_tick_us_ - boot_us_);
      a.frames.Tick();
      next_tick_us_ += a.frames.period_us();
    }
    // Said once per acquisition: a test waits for the state it acts on (a Ctrl-C while the board
    // samples) instead of guessing it with a sleep.
    if (options_.verbose && a.frames.Running() != was_sampling_)
      std::fprintf(stderr, "vibid-emu: sampling %s\n", was_sampling_ ? "stopped" : "started");
    was_sampling_ = a.frames.Running();
  }
  sim_us_ = frame_end;
  if (!app_) return;
  app_->clock.Set(sim_us_ - boot_us_);
  RunFirmware();
  // The frame's transactions, then the main loop reacts (answers a request, arms the next report).
  app_->exported.StartFrame(!options_.beyond_board, frame_end - kFrameUs);
  app_->exported.Service();
  app_->exported.EndFrame();
  RunFirmware();
}

void Emulator::AdvanceTime() {
  const Clock::time_point now = Clock::now();
  const auto wall_us = static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::microseconds>(now - last_wall_).count());
  last_wall_ = now;
  const bool sampling = app_ && app_->frames.Running();
  if (!Busy() || (options_.speed > 0.0 && !sampling)) {
    // Idle, or a paced emulator that is not sampling: the clock follows the wall clock, frame by
    // frame (a request still takes a frame, a paced log pull runs at the board's real pace).
    pacing_ = false;
    idle_us_ = std::min<std::uint64_t>(idle_us_ + wall_us, 100 * kFrameUs);
    for (; idle_us_ >= kFrameUs; idle_us_ -= kFrameUs) {
      if (!Busy()) {
        RunFrame();
      } else if (options_.speed > 0.0 && !WaitForHost(now)) {
        RunFrame();
      } else {
        break;
      }
    }
    if (Busy() && options_.speed <= 0.0) idle_us_ = 0;
    return;
  }
  idle_us_ = 0;
  int frames = kChunkFrames;
  if (options_.speed > 0.0) {
    if (!pacing_) {
      pacing_ = true;
      pace_wall_ = now;
      pace_sim_us_ = sim_us_;
    }
    const double elapsed_us = static_cast<double>(
        std::chrono::duration_cast<std::chrono::microseconds>(now - pace_wall_).count());
    const double behind = static_cast<double>(pace_sim_us_) + elapsed_us * options_.speed -
                          static_cast<double>(sim_us_);
    frames = behind <= 0.0
                 ? 0
                 : static_cast<int>(std::min<double>(kChunkFrames, behind / kFrameUs + 1.0));
  }
  for (int i = 0; i < frames && Busy(); ++i) {
    if (WaitForHost(now)) return;
    RunFrame();
  }
}

void Emulator::HandleRequests() {
  if (bootloader_) {
    if (bootloader_->leave_requested()) BootApplication(wire::ResetCause::kSoftware);
    return;
  }
  Application& a = *app_;
  if (a.request == Request::kNone) {
    a.request = a.system.TakeRequest();
    if (a.request == Request::kNone) return;
    request_deadline_ = Clock::now() + kRequestGrace;
  }
  // Let the host collect the answer to the command first, as the board's USB FIFO would drain.
  if (!a.hid.CanSend() && a.hid.is_open() && Clock::now() < request_deadline_) return;
  if (a.request == Request::kReset) {
    BootApplication(wire::ResetCause::kSoftware);
  } else {
    EnterBootloader();
  }
}

void Emulator::Step(std::chrono::milliseconds max_wait) {
  // Flat out, the loop only sleeps on the sockets while a frame waits for the host's URB: its
  // arrival is what lets time go on.
  const bool pending = app_ && app_->request != Request::kNone;
  const bool flat_out = Busy() && options_.speed <= 0.0 && !waiting_;
  const auto wait = flat_out || pending ? std::chrono::milliseconds(0)
                    : Busy()            ? std::chrono::milliseconds(1)
                                        : std::min(max_wait, std::chrono::milliseconds(1));
  // Drain every message that is already there before the firmware runs.
  bool handled = server_.Poll(wait);
  for (int more = 0; handled && more < 64; ++more)
    handled = server_.Poll(std::chrono::milliseconds(0));
  RunFirmware();
  AdvanceTime();
  HandleRequests();
}

void Emulator::Run(const std::atomic<bool>& stop) {
  while (!stop.load(std::memory_order_relaxed)) Step();
}

}  // namespace vibid::emu
