// Command family registration (filled in as the family's commands land).
#include "commands.hpp"

namespace vibid::cli {

void RegisterDobCommands(CLI::App& /*app*/) {}

}  // namespace vibid::cli
