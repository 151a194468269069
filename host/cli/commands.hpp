// Each command family registers its subcommands on the app. One family per folder under host/cli.
#pragma once

#include <CLI/CLI.hpp>

namespace vibid::cli {

/// Options given before the subcommand, shared by every command that talks to a board.
struct GlobalOptions {
  std::string device;  ///< `hid[:SERIAL]`, `usbip://HOST:PORT`, `serial:/dev/ttyX`, `qemu`; empty:
                       ///< the only one found.
};

void RegisterModelCommands(CLI::App& app);  // modal, frf, simulate
void RegisterIdentCommands(CLI::App& app);  // frf-estimate, modes, update, decay, identify
void RegisterSysidCommands(CLI::App& app);  // arx, pem, tfest, compare, greybox
void RegisterDobCommands(CLI::App& app,
                         const GlobalOptions& globals);  // dob design|run|compare|start|stop
void RegisterReportCommands(CLI::App& app);              // report
void RegisterDeviceCommands(CLI::App& app,
                            const GlobalOptions& globals);  // devices, info, cal, acquire, ...

}  // namespace vibid::cli
