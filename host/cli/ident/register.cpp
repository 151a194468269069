// The identification family: frf-estimate, modes, update mass|stiffness, decay, identify.
#include "commands.hpp"
#include "ident_commands.hpp"

namespace vibid::cli {

void RegisterIdentCommands(CLI::App& app) {
  RegisterFrfEstimate(app);
  RegisterModes(app);
  RegisterUpdate(app);
  RegisterDecay(app);
  RegisterIdentify(app);
}

}  // namespace vibid::cli
