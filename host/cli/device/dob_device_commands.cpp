// vibid dob start | stop: run or halt the observer on the board. The `dob` command itself belongs
// to the observer design family (dob design|run|compare); these join it as two more subcommands.
#include <iostream>

#include "device_commands.hpp"
#include "session.hpp"

namespace vibid::cli {

void RegisterDobControlCommands(CLI::App& app, const GlobalOptions& globals) {
  CLI::App* dob = nullptr;
  try {
    dob = app.get_subcommand("dob");
  } catch (const CLI::OptionNotFound&) {
    dob = app.add_subcommand("dob", "Disturbance observer: design on the host, run on the board");
    dob->require_subcommand(1);
  }
  CLI::App* start = dob->add_subcommand("start", "Run the observer on the board (from zero state)");
  start->callback([&globals] {
    WithDevice(globals, [](device::Connection& c) {
      c.DobControl(true);
      std::cout << "observer running\n";
    });
  });
  CLI::App* stop = dob->add_subcommand("stop", "Stop the observer on the board");
  stop->callback([&globals] {
    WithDevice(globals, [](device::Connection& c) {
      c.DobControl(false);
      std::cout << "observer stopped\n";
    });
  });
}

}  // namespace vibid::cli
