// The device command family: everything that talks to a board (or the emulator).
#include "commands.hpp"
#include "device_commands.hpp"

namespace vibid::cli {

void RegisterDeviceCommands(CLI::App& app, const GlobalOptions& globals) {
  RegisterInfoCommands(app, globals);
  RegisterCalCommands(app, globals);
  RegisterAcquireCommands(app, globals);
  RegisterFlashCommand(app, globals);
  RegisterSelfTestCommand(app, globals);
  RegisterBenchCommand(app, globals);
  RegisterWatchCommand(app, globals);
}

}  // namespace vibid::cli
