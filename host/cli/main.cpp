// `vibid`: one binary, one subcommand per job. Every failure prints one line naming the problem on
// stderr and exits with a code from exit_codes.hpp.
#include <exception>
#include <iostream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli_support.hpp"
#include "commands.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/memory_policy.hpp"
#include "vibid/device/error.hpp"

int main(int argc, char** argv) {
  using namespace vibid::cli;
  vibid::KeepFreedMemory();
  CLI::App app{
      "vibid: identify mass-spring vibration rigs and run a disturbance observer on the DAQ "
      "board.\n"
      "SI units throughout: kg, N/m, N*s/m, s, rad/s; frequencies in Hz are named *_hz.",
      "vibid"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("vibid ") + VIBID_VERSION);
  GlobalOptions globals;
  app.add_option("--device", globals.device,
                 "Board to talk to: hid[:SERIAL] | usbip://HOST:PORT | serial:/dev/ttyX | qemu; "
                 "before or after a device command's name. Default: the VIBID_DEVICE environment "
                 "variable (the option wins over it), else the only board found");

  RegisterModelCommands(app);
  RegisterIdentCommands(app);
  RegisterSysidCommands(app);
  RegisterDobCommands(app, globals);
  RegisterReportCommands(app);
  RegisterDeviceCommands(app, globals);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // A value out of its range or not of its kind is bad input, like a bad file: one line, exit 1.
    // Usage errors (unknown or missing options) keep CLI11's message and exit 2.
    if (dynamic_cast<const CLI::ValidationError*>(&e) ||
        dynamic_cast<const CLI::ConversionError*>(&e)) {
      std::cerr << "vibid: error: " << e.what() << "\n";
      return kExitInputError;
    }
    // A misspelt command or option is named, with the nearest known one.
    if (e.get_exit_code() != 0) {
      const std::string unknown =
          UnknownWordMessage(app, std::vector<std::string>(argv + 1, argv + argc));
      if (!unknown.empty()) {
        std::cerr << "vibid: error: " << unknown << "\n";
        return kExitUsage;
      }
    }
    const int code = app.exit(e);
    return code == 0 ? kExitOk : kExitUsage;
  } catch (const vibid::InputError& e) {
    std::cerr << "vibid: error: " << e.what() << "\n";
    return kExitInputError;
  } catch (const NumericalError& e) {
    std::cerr << "vibid: error: " << e.what() << "\n";
    return kExitNumerical;
  } catch (const ResultCaution& e) {
    std::cerr << "vibid: caution: " << e.what() << "\n";
    return kExitCaution;
  } catch (const StoppedByInterrupt&) {
    return kExitInterrupted;  // the command said what it kept
  } catch (const vibid::device::Interrupted& e) {
    std::cerr << "vibid: " << e.what() << "\n";
    return kExitInterrupted;
  } catch (const vibid::device::DeviceError& e) {
    std::cerr << "vibid: error: " << e.what() << "\n";
    return kExitDevice;
  } catch (const std::exception& e) {
    std::cerr << "vibid: internal error: " << e.what() << "\n";
    return kExitInternal;
  }
  return kExitOk;
}
