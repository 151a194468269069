// Registration of the device command family, one function per source file.
#pragma once

#include <CLI/CLI.hpp>

#include "commands.hpp"

namespace vibid::cli {

void RegisterInfoCommands(CLI::App& app, const GlobalOptions& globals);     // devices, info, monitor
void RegisterCalCommands(CLI::App& app, const GlobalOptions& globals);      // cal upload|show|commit
void RegisterAcquireCommands(CLI::App& app, const GlobalOptions& globals);  // acquire, log pull
void RegisterDobControlCommands(CLI::App& app, const GlobalOptions& globals);  // dob start|stop
void RegisterFlashCommand(CLI::App& app, const GlobalOptions& globals);     // flash

}  // namespace vibid::cli
