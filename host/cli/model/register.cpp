// Command family registration (filled in as the family's commands land).
#include "commands.hpp"

namespace vibid::cli {

void RegisterModelCommands(CLI::App& /*app*/) {}

}  // namespace vibid::cli
