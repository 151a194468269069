// `vibid dob start | stop`: run or halt the observer on the board. They sit beside the observer's
// design commands under `vibid dob`, which registers them (dob/dob_commands.cpp).
#include <iostream>

#include "common/command.hpp"
#include "device_commands.hpp"
#include "session.hpp"

namespace vibid::cli {
namespace {

constexpr const char* kDobStartHelp = "Run the observer on the board (from zero state)";
constexpr const char* kDobStopHelp = "Stop the observer on the board";

struct DobControlArgs {
  const GlobalOptions* globals = nullptr;
  bool running = false;  ///< The state the board is asked into.
};

void Run(const DobControlArgs& a) {
  WithDevice(*a.globals, [&](device::Connection& c) {
    c.DobControl(a.running);
    // The board samples only while an acquisition runs: say when the observer will step.
    std::cout << (a.running ? "observer on: it steps on every sample of the acquisitions that "
                              "follow (the board samples only while one runs)\n"
                            : "observer off\n");
  });
}

}  // namespace

void RegisterDobDeviceCommands(CLI::App& dob, const GlobalOptions& globals) {
  const auto [start, start_args] = AddCommand<DobControlArgs>(dob, "start", kDobStartHelp, Run);
  *start_args = {.globals = &globals, .running = true};
  TakesDeviceOption(start);
  const auto [stop, stop_args] = AddCommand<DobControlArgs>(dob, "stop", kDobStopHelp, Run);
  *stop_args = {.globals = &globals, .running = false};
  TakesDeviceOption(stop);
}

}  // namespace vibid::cli
