// `vibid decay`: free-decay analysis of pull-and-release records.
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "common/command.hpp"
#include "ident_commands.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/workflow/decay_run.hpp"
#include "vibid/common/error.hpp"
#include "vibid/ident/decay.hpp"

namespace vibid::cli {

namespace {

constexpr const char* kDecayHelp =
    "Free decay after a pull and release (no force channel): finds the release, fits x = x0 + A "
    "exp(-sigma t)\n"
    "cos(omega_d t + phi) over the first cycles, gives omega_d, zeta, omega_n (repeats averaged). "
    "With --loaded\n"
    "records of the same spring carrying --added-kg more, solves k and the base mass.";

struct DecayArgs {
  workflow::DecayRequest request;
  bool json = false;
  std::string output;
};

void Run(const DecayArgs& a) {
  const nlohmann::json j = workflow::RunDecay(a.request);
  EmitOutput(a.json ? j.dump(2) + "\n" : workflow::DecayText(j), a.output);
  SayCautions(j["cautions"].get<std::vector<std::string>>(), "the decay");
}

}  // namespace

void RegisterDecay(CLI::App& app) {
  const auto [cmd, a] = AddCommand<DecayArgs>(app, "decay", kDecayHelp, Run);
  cmd->add_option("recordings", a->request.recordings,
                  "Record(s) of the base configuration, REC.csv ...")
      ->required();
  cmd->add_option("--position", a->request.position,
                  "Position column, NAME[:UNIT|*FACTOR] (e.g. X_cm:cm)")
      ->required();
  cmd->add_option("--scale", a->request.scale,
                  "Extra factor applied to the position (e.g. counts to metres)")
      ->check(PositiveNumber());
  cmd->add_option("--fs-hz", a->request.fs_hz, "Sample rate (Hz) when the file has no t_s column")
      ->check(PositiveNumber());
  cmd->add_option(
         "--cycles", a->request.options.cycles,
         "Cycles after the release in the fit (0: until the envelope falls below --end-fraction); "
         "friction\n"
         "makes damping grow as the amplitude falls, so the first cycles are the comparable ones")
      ->capture_default_str();
  cmd->add_option("--end-fraction", a->request.options.end_fraction,
                  "With --cycles 0: stop where the envelope falls below this fraction")
      ->capture_default_str();
  cmd->add_option("--loaded", a->request.loaded,
                  "Record(s) with the added mass, for k and the base mass");
  cmd->add_option("--added-kg", a->request.added_kg, "Mass added in the --loaded records (kg)")
      ->check(PositiveNumber());
  cmd->add_flag("--json", a->json, "JSON output");
  cmd->add_option("-o,--output", a->output, "Write the result here instead of stdout");
}

}  // namespace vibid::cli
