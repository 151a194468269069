// Command family registration (filled in as the family's commands land).
#include "commands.hpp"

namespace vibid::cli {

void RegisterDeviceCommands(CLI::App& /*app*/, const GlobalOptions& /*globals*/) {}

}  // namespace vibid::cli
