// System identification: arx, pem, tfest, compare, greybox.
#include "commands.hpp"
#include "sysid/sysid_cli.hpp"

namespace vibid::cli {

void RegisterSysidCommands(CLI::App& app) {
  RegisterArxCommand(app);
  RegisterPemCommand(app);
  RegisterTfestCommand(app);
  RegisterCompareCommand(app);
  RegisterGreyboxCommand(app);
}

}  // namespace vibid::cli
