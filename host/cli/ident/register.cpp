// Command family registration (filled in as the family's commands land).
#include "commands.hpp"

namespace vibid::cli {

void RegisterIdentCommands(CLI::App& /*app*/) {}

}  // namespace vibid::cli
