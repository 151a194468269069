// vibid-emu: the firmware core on the host, wired to the simulated rig and exported as a USB
// device over USB/IP. One thread runs everything: socket I/O, the firmware's main loop
// (USB stack task, core poll) and simulated time (one rig step per sample tick).
//
// Time: simulated time advances in 1 ms USB frames. In each frame the sampling interrupt runs
// for the ticks that fall in it (the rig steps once per tick), the firmware's main loop runs, and
// the HID link moves at most one IN and one OUT report (full speed, bInterval 1: 64 000 B/s each
// way), exactly the board's limits (vibid/shared/board_profile.hpp), with the board's log size.
// Flat out (`speed` 0) frames follow each other as fast as the CPU allows while the board samples
// or has a report to send; at a set speed they are paced to `speed` x real time; otherwise the
// clock follows the wall clock.
//
// What the host sees must not depend on how fast it or the emulator runs. The one wait allowed
// is the one a real host makes impossible: when the device has a report ready and no IN URB of
// the host is queued, the next frame waits for one, because a real host (the kernel's HID
// driver) polls the endpoint every frame and would have taken the report in this one. The board
// never waits for anything else: a host that does not ask for the log sees it fill and drop
// records, counted, as on a board. So the same seed and commands give the same bytes and the same
// drop counts on an idle or a loaded machine and at any speed. `beyond_board` lifts the link
// limit and allows another log size, for experiments only.
//
// Personalities: the application (core + HID + DFU run-time), or the DfuSe bootloader after
// enter-DFU / DFU_DETACH. Each switch, and a reset, drops the importing USB/IP connection:
// the device re-enumerates, and the client imports it again.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "dfuse_bootloader.hpp"
#include "flash_image.hpp"
#include "rig.hpp"
#include "usbip_server.hpp"
#include "vibid/shared/board_profile.hpp"
#include "vibid/shared/wire/device.hpp"

namespace vibid::emu {

struct EmulatorOptions {
  RigSpec rig = DefaultRig();
  std::string flash_path;  ///< empty: flash in memory only
  std::uint64_t seed = 1;
  std::string bind_address = "127.0.0.1";
  std::uint16_t port = 3240;  ///< 0: any free port (tests)
  double speed = 0.0;         ///< simulated s per wall s while sampling; 0 = as fast as possible
  std::size_t log_bytes = kBoardProfile.log_bytes;
  /// Experiments only: no per-frame report limit, any log size. Never used by tests or the demo.
  bool beyond_board = false;
  bool verbose = false;  ///< one line per personality change and USB/IP import on stderr
};

class Emulator {
 public:
  /// How long a frame waits for a host's IN URB before it counts the host as gone (a host that
  /// stopped polling: the board then keeps its report and goes on sampling).
  static constexpr std::chrono::seconds kHostGone{5};

  /// @throws InputError for a bad rig or flash file; usbip::IoError when the port is taken.
  explicit Emulator(EmulatorOptions options);
  ~Emulator();
  Emulator(const Emulator&) = delete;
  Emulator& operator=(const Emulator&) = delete;

  std::uint16_t port() const { return server_.port(); }
  std::string serial() const { return serial_; }

  /// One loop iteration: I/O (waiting at most `max_wait` when there is nothing else to do), the
  /// firmware's main loop, simulated time, personality changes.
  void Step(std::chrono::milliseconds max_wait = std::chrono::milliseconds(5));

  /// Steps until `stop` becomes true.
  void Run(const std::atomic<bool>& stop);

  bool InBootloader() const { return bootloader_ != nullptr; }
  /// Simulated microseconds since the emulator started.
  std::uint64_t SimulatedUs() const { return sim_us_.load(std::memory_order_acquire); }
  /// When, in simulated time, sampling last started and an IN report last left: the timing of
  /// an acquisition as the board produced it, which another thread cannot read off SimulatedUs()
  /// without racing the idle clock.
  std::uint64_t SamplingStartUs() const {
    return sampling_start_us_.load(std::memory_order_acquire);
  }
  std::uint64_t LastInReportUs() const {
    return last_in_report_us_.load(std::memory_order_acquire);
  }

 private:
  struct Application;

  void BootApplication(wire::ResetCause cause);
  void EnterBootloader();
  void RunFirmware();
  void AdvanceTime();
  /// One USB frame of simulated time: its sample ticks, the main loop, its link transactions.
  void RunFrame();
  /// The board is sampling or has a report to send: flat out, frames need not wait for the clock.
  bool Busy() const;
  /// The next frame must wait for the host's IN URB (see the header comment).
  bool WaitForHost(std::chrono::steady_clock::time_point now);
  void HandleRequests();
  usbip::UsbDevice Record() const;

  EmulatorOptions options_;
  std::string serial_;
  FlashImage flash_;
  RigSimulator rig_;
  UsbIpServer server_;
  std::vector<std::uint8_t> log_;
  std::unique_ptr<Application> app_;
  std::unique_ptr<DfuSeBootloader> bootloader_;

  // Written by the emulator's thread only; atomic so that tests may read them from theirs.
  std::atomic<std::uint64_t> sim_us_{0};
  std::atomic<std::uint64_t> sampling_start_us_{0};
  std::atomic<std::uint64_t> last_in_report_us_{0};
  std::uint64_t boot_us_ = 0;  // sim_us_ when the application last booted (its clock's zero)
  std::chrono::steady_clock::time_point last_wall_;
  // Pacing anchor for a sampling run at a set speed.
  bool pacing_ = false;
  std::chrono::steady_clock::time_point pace_wall_;
  std::uint64_t pace_sim_us_ = 0;
  // Sampling: the simulated time of the next tick; whether the last frame sampled.
  bool was_sampling_ = false;
  std::uint64_t next_tick_us_ = 0;
  // Wall time the simulated clock follows while idle (whole frames; the rest carries over).
  std::uint64_t idle_us_ = 0;
  // Since when the next frame waits for a host's IN URB.
  bool waiting_ = false;
  std::chrono::steady_clock::time_point waiting_since_{};
  // A reset or DFU entry waits for its answer to leave the IN endpoint (or a short deadline).
  std::chrono::steady_clock::time_point request_deadline_{};
};

}  // namespace vibid::emu
