// vibid bench: the live bench, a local web page over the board (host/bench). It holds the board
// (one bench per board, as any command holds it) until Ctrl-C.
#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>
#include <thread>

#include "cli_support.hpp"
#include "common/command.hpp"
#include "device_commands.hpp"
#include "session.hpp"
#include "vibid/bench/bench_board.hpp"
#include "vibid/bench/calibration_routes.hpp"
#include "vibid/bench/identify_routes.hpp"
#include "vibid/bench/hammer_routes.hpp"
#include "vibid/bench/watch_routes.hpp"
#include "vibid/bench/server.hpp"
#include "vibid/workflow/watch_metrics.hpp"

namespace vibid::cli {
namespace {

constexpr const char* kBenchHelp =
    "Serve the live bench: a local web page with the board and a live scope, hammer tests hit by "
    "hit\n"
    "(verdicts, running FRF and modes), identification, observer design and calibration upload, "
    "and the\n"
    "observer's running fit. Prints its URL (with its access token) first; Ctrl-C stops a running\n"
    "acquisition keeping what it recorded, and ends the bench (exit 130)";

struct BenchArgs {
  const GlobalOptions* globals = nullptr;
  std::string bind = "127.0.0.1";
  int port = 0;
  std::string out = "vibid-bench";  // under the current directory
  bool metrics = false;             // GET /metrics for Prometheus
  std::string metrics_rig = "bench";
  std::string token_file;  // the bench's token kept in a file (read, or written)
};

void Run(const BenchArgs& a) {
  if (!bench::IsLoopback(a.bind)) {
    std::cerr << "vibid: warning: --bind " << a.bind
              << ": the bench is reachable from the network; anyone with its URL (token) can "
                 "reconfigure the board\n";
  }
  WithDevice(
      *a.globals,
      [&](device::Connection& c) {
        bench::LiveHub hub;
        bench::BenchBoard board(c, a.out, hub, &InterruptFlag());
        const std::string token = a.token_file.empty() ? "" : bench::TokenFromFile(a.token_file);
        bench::BenchServer server(board, hub, {.bind = a.bind, .port = a.port, .token = token});
        // Every view on the directory the board resolved once, never the raw -o again.
        const std::string& dir = board.directory();
        bench::AddCalibrationRoutes(server, board, dir, VIBID_VERSION);
        bench::AddIdentifyRoutes(server, board, dir);
        const auto hammer = bench::AddHammerRoutes(server, board, hub, dir);
        const auto watch = bench::AddWatchRoutes(
            server, board, hub, dir,
            a.metrics ? std::make_shared<workflow::WatchMetrics>(a.metrics_rig) : nullptr);
        server.Start();
        std::cout << server.Url() << std::endl;
        if (a.metrics) {
          std::cerr << "vibid: the Watch view's metrics on " << bench::UrlHost(a.bind) << ":"
                    << server.port() << bench::kMetricsPath << " (rig \"" << a.metrics_rig
                    << "\"; the token as a bearer token)\n";
        }
        std::cerr << "vibid: bench on " << c.Describe() << ", recordings in " << dir
                  << "; Ctrl-C ends it\n";
        while (!InterruptFlag().load()) std::this_thread::sleep_for(std::chrono::milliseconds(100));
        std::cerr << "vibid: Ctrl-C: stopping, keeping what was recorded\n";
        board.Shutdown();
        const nlohmann::json st = board.State();
        if (st.contains("file"))
          std::cerr << "vibid: " << st["records"] << " records in " << st["file"].get<std::string>()
                    << "\n";
        server.Stop();
      },
      CtrlC::kStopsAcquisition);
  throw StoppedByInterrupt();
}

}  // namespace

void RegisterBenchCommand(CLI::App& app, const GlobalOptions& globals) {
  const auto [cmd, o] = AddCommand<BenchArgs>(app, "bench", kBenchHelp, Run);
  o->globals = &globals;
  TakesDeviceOption(cmd);
  cmd->add_option("--port", o->port, "TCP port (0: a free one)")
      ->check(CLI::Range(0, 65535))
      ->capture_default_str();
  cmd->add_option("--bind", o->bind,
                  "Address to listen on (default 127.0.0.1; another one is reachable from the "
                  "network and is warned about)")
      ->capture_default_str();
  cmd->add_option(
         "-o,--out", o->out,
         "Directory for the recordings (journals while they run), saved tests and the files the\n"
         "calibration view reads and writes (created; its full path is printed)")
      ->capture_default_str();
  auto* metrics = cmd->add_flag("--metrics", o->metrics,
                                "Serve the Watch view's figures to Prometheus at /metrics (the "
                                "bench's token as a bearer token)");
  cmd->add_option("--metrics-rig", o->metrics_rig, "The rig label of every metric")
      ->capture_default_str()
      ->needs(metrics);
  cmd->add_option("--token-file", o->token_file,
                  "Keep the bench's token in this file: read, or a new one written there "
                  "readable by you only (a scraper's credentials_file)");
}

}  // namespace vibid::cli
