// vibid-emu: the DAQ board's firmware on the host with a simulated rig, exported over USB/IP.
#include <csignal>
#include <cstdio>
#include <iostream>

#include <CLI/CLI.hpp>

#include "emulator.hpp"
#include "vibid/common/error.hpp"
#include "vibid/usbip/socket.hpp"

namespace {

std::atomic<bool> g_stop{false};

void OnSignal(int) { g_stop.store(true); }

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "vibid-emu: the vibid DAQ board emulated on this host, with a simulated rig, "
      "exported as a USB device over USB/IP"};
  std::string rig_path;
  std::string bind = "127.0.0.1";
  int port = 3240;
  std::string flash_path;
  std::uint64_t seed = 1;
  bool realtime = false;
  double speed = 0.0;
  std::size_t log_kib = vibid::kBoardProfile.log_bytes / 1024;
  bool beyond_board = false;
  bool print_truth = false;
  double truth_at_s = 0.0;
  bool verbose = false;
  app.add_option("--rig", rig_path, "rig file (JSON); default: the built-in 2-DOF chain");
  app.add_option("--bind", bind, "IPv4 address to listen on")->capture_default_str();
  app.add_option("--port", port, "TCP port of the USB/IP server (0: any free port)")
      ->capture_default_str();
  app.add_option("--flash", flash_path,
                 "file holding the board's 1 MiB flash (calibration slots and firmware image); "
                 "default: flash in memory only");
  app.add_option("--seed", seed, "seed of the rig's excitation and sensor noise")
      ->capture_default_str();
  app.add_flag("--realtime", realtime,
               "run simulated time at wall-clock speed (same as --speed 1)");
  app.add_option(
         "--speed", speed,
         "simulated seconds per wall second while sampling (0: as fast as possible); what is "
         "sampled, logged, dropped and delivered is the same at any speed")
      ->check(CLI::NonNegativeNumber);
  app.add_flag(
      "--beyond-board", beyond_board,
      "experiments only: lift the board's limits (no one-report-per-frame link limit; --log-kib "
      "takes any size). Without it the emulator is the board.");
  app.add_option("--log-kib", log_kib,
                 "acquisition log size in KiB (needs --beyond-board; default: the board's)")
      ->check(CLI::Range(1, 262144))
      ->capture_default_str();
  app.add_flag("--print-truth", print_truth,
               "print the rig's true model (model-file JSON) and exit");
  app.add_option("--at-s", truth_at_s,
                 "with --print-truth: the truth this many seconds after an acquisition's start, "
                 "with the rig file's changes in force then (default 0)")
      ->check(CLI::NonNegativeNumber);
  app.add_flag(
      "-v,--verbose", verbose,
      "report personality changes, USB/IP clients and when sampling starts and stops on stderr");
  CLI11_PARSE(app, argc, argv);

  try {
    vibid::emu::EmulatorOptions options;
    if (!rig_path.empty()) options.rig = vibid::emu::LoadRig(rig_path);
    if (print_truth) {
      std::cout << vibid::emu::TruthToJson(options.rig, truth_at_s).dump(2) << "\n";
      return 0;
    }
    vibid::Require(truth_at_s == 0.0, "--at-s goes with --print-truth");
    vibid::Require(port >= 0 && port <= 65535, "--port must be 0..65535");
    options.flash_path = flash_path;
    options.seed = seed;
    options.bind_address = bind;
    options.port = static_cast<std::uint16_t>(port);
    options.speed = realtime ? 1.0 : speed;
    vibid::Require(beyond_board || log_kib * 1024 == vibid::kBoardProfile.log_bytes,
                   "--log-kib: the board's log is " +
                       std::to_string(vibid::kBoardProfile.log_bytes / 1024) +
                       " KiB; another size needs --beyond-board");
    options.log_bytes = log_kib * 1024;
    options.beyond_board = beyond_board;
    options.verbose = verbose;
    vibid::emu::Emulator emulator(options);

    std::signal(SIGINT, OnSignal);
    std::signal(SIGTERM, OnSignal);
    std::printf("vibid-emu: USB/IP on %s:%u, bus id %s, serial %s, %s rig, seed %llu, flash %s\n",
                bind.c_str(), static_cast<unsigned>(emulator.port()),
                vibid::emu::UsbIpServer::kBusId, emulator.serial().c_str(),
                rig_path.empty() ? "built-in" : rig_path.c_str(),
                static_cast<unsigned long long>(seed),
                flash_path.empty() ? "in memory" : flash_path.c_str());
    std::fflush(stdout);
    emulator.Run(g_stop);
    return 0;
  } catch (const vibid::InputError& e) {
    std::fprintf(stderr, "vibid-emu: %s\n", e.what());
    return 1;
  } catch (const vibid::usbip::IoError& e) {
    std::fprintf(stderr, "vibid-emu: %s\n", e.what());
    return 1;
  }
}
