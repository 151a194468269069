// vibid-emu: the firmware core on the host, wired to the simulated rig and exported as a USB
// device over USB/IP. One thread runs everything: socket I/O, the firmware's main loop
// (USB stack task, core poll) and simulated time (one rig step per sample tick).
//
// Time: the simulated clock only moves in the loop. While the core samples, ticks run in chunks
// as fast as the host CPU allows (`speed` 0), or paced at `speed` × real time; while it does not,
// the clock follows the wall clock. Samples depend only on the seed and the commands, never on
// how fast the loop ran.
//
// Back-pressure (`speed` 0 only): flat out, the rig produces log data about ten times faster than
// a host pulls it over USB/IP (bench/emu), and a board's full log drops records. Since the clock is
// virtual anyway, simulated time waits instead while a host is pulling and the next record would
// find the log full. "Pulling" means a log-read stream is being sent, or the log's release point
// advanced less than kPullWindow of wall time ago; the host that starts an acquisition gets the
// same window to begin. With nobody pulling, the log fills and drops records (counted) as on a
// board. At a set speed (`--realtime`, `--speed N`) time never waits: that is the board's case.
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
#include "vibid/shared/wire/device.hpp"

namespace vibid::emu {

struct EmulatorOptions {
  RigSpec rig = DefaultRig();
  std::string flash_path;  ///< empty: flash in memory only
  std::uint64_t seed = 1;
  std::string bind_address = "127.0.0.1";
  std::uint16_t port = 3240;  ///< 0: any free port (tests)
  double speed = 0.0;         ///< simulated s per wall s while sampling; 0 = as fast as possible
  std::size_t log_bytes = 4 * 1024 * 1024;
  bool verbose = false;       ///< one line per personality change and USB/IP import on stderr
};

class Emulator {
 public:
  /// How long after its last log-read (or the acquisition start) a host still counts as pulling.
  static constexpr std::chrono::milliseconds kPullWindow{500};

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
  std::uint64_t SimulatedUs() const { return sim_us_; }

 private:
  struct Application;

  void BootApplication(wire::ResetCause cause);
  void EnterBootloader();
  void RunFirmware();
  void AdvanceTime();
  /// Back-pressure: true while a pulling host would lose the next record to a full log.
  bool WaitForPull(std::chrono::steady_clock::time_point now);
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

  std::uint64_t sim_us_ = 0;
  std::chrono::steady_clock::time_point last_wall_;
  // Pacing anchor for a sampling run at a set speed.
  bool pacing_ = false;
  std::chrono::steady_clock::time_point pace_wall_;
  std::uint64_t pace_sim_us_ = 0;
  // Back-pressure state: the log's release point last seen and when it last advanced (or the
  // acquisition started); whether time waited in the last step.
  bool was_sampling_ = false;
  std::uint32_t seen_released_ = 0;
  std::chrono::steady_clock::time_point last_pull_{};
  bool waiting_for_pull_ = false;
  // A reset or DFU entry waits for its answer to leave the IN endpoint (or a short deadline).
  std::chrono::steady_clock::time_point request_deadline_{};
};

}  // namespace vibid::emu
