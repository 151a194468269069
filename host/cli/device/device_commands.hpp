// Registration of the device command family, one function per source file.
#pragma once

#include <CLI/CLI.hpp>

#include "commands.hpp"

namespace vibid::cli {

void RegisterInfoCommands(CLI::App& app, const GlobalOptions& globals);  // devices, info, monitor
void RegisterCalCommands(CLI::App& app, const GlobalOptions& globals);   // cal upload|show|commit
void RegisterAcquireCommands(CLI::App& app, const GlobalOptions& globals);  // acquire, log pull
/// Adds `start` and `stop` to the `dob` command (registered by RegisterDobCommands).
void RegisterDobDeviceCommands(CLI::App& dob, const GlobalOptions& globals);
void RegisterFlashCommand(CLI::App& app, const GlobalOptions& globals);     // flash
void RegisterSelfTestCommand(CLI::App& app, const GlobalOptions& globals);  // selftest
void RegisterBenchCommand(CLI::App& app, const GlobalOptions& globals);     // bench
void RegisterWatchCommand(CLI::App& app, const GlobalOptions& globals);     // watch

}  // namespace vibid::cli
