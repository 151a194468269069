// `vibid frf-estimate` and `vibid modes`.
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "cli_support.hpp"
#include "common/command.hpp"
#include "vibid/common/option_text.hpp"
#include "ident_cli.hpp"
#include "ident_commands.hpp"
#include "vibid/common/error.hpp"
#include "vibid/ident/frf_io.hpp"
#include "vibid/ident/modes.hpp"

namespace vibid::cli {

namespace {

constexpr const char* kFrfEstimateHelp =
    "Estimate FRFs (H1/H2/Hv with coherence) of responses to a force from a recording: one record "
    "per hammer\n"
    "hit with force and exponential windows and double-hit/clipping checks when the force is a "
    "train of short\n"
    "pulses (or --impact), Welch averaging otherwise (or --welch).";

struct FrfEstimateArgs {
  std::string input;
  std::string output;
  int reference_node = 0;
  EstimationArgs est;
};

void Run(const FrfEstimateArgs& a) {
  const Estimated e = EstimateFromRecording(a.input, a.est);
  if (!e.note.empty()) std::cerr << "vibid: note: " << e.note << "\n";
  for (const std::string& w : e.warnings) std::cerr << "vibid: warning: " << w << "\n";
  const int ref = a.reference_node > 0 ? a.reference_node : static_cast<int>(e.frf.responses());
  if (a.output.empty() || a.output == "-")
    EmitOutput(ident::FormatFrfForPath(e.frf, a.output, ref), a.output);
  else
    ident::WriteFrf(e.frf, a.output, ref);
  if (!a.output.empty() && a.output != "-") {
    std::ostringstream msg;
    msg << "wrote " << a.output << ": " << ident::FrfKindName(e.frf.quantity) << ", "
        << e.frf.lines() << " lines, " << e.frf.responses() << " response(s), " << e.frf.averages
        << " average(s)\n"
        << e.compensation << DescribeHits(e.hits);
    std::cout << msg.str();
  } else {
    std::cerr << e.compensation << DescribeHits(e.hits);
  }
}

constexpr const char* kModesHelp =
    "Modal parameters (omega, zeta, mass-normalised shapes, a1/a2) from FRFs of one hammer test. "
    "Inputs are FRF files\n"
    "(CSV from frf-estimate, or UFF58) or recordings, which are estimated first; several inputs "
    "are joined as responses.";

struct ModesArgs {
  std::vector<std::string> inputs;
  bool json = false;
  std::string output;
  EstimationArgs est;
  ModeArgs modes;
};

void Run(const ModesArgs& a) {
  const workflow::ModesOfInputs m = workflow::IdentifyModesOf(a.inputs, a.est, a.modes);
  for (std::size_t i = 0; i < m.estimation_notes.size(); ++i) {
    if (!m.estimation_notes[i].empty())
      std::cerr << "vibid: note: " << m.estimation_notes[i] << "\n";
    for (const std::string& w : m.estimation_warnings[i])
      std::cerr << "vibid: warning: " << w << "\n";
  }
  if (m.driving_point.how == "found" && m.frf.responses() > 1)
    std::cerr << "vibid: note: " << m.driving_point.note << "\n";
  const ident::ModeIdentification& r = m.identification;
  const ident::Frf& frf = m.frf;
  const std::vector<std::string>& notes = m.notes;
  EmitOutput(
      a.json
          ? workflow::ModeIdentificationJson(r, a.modes.method, frf.response_names, notes).dump(2) +
                "\n"
          : workflow::ModeIdentificationText(r),
      a.output);
  for (const auto& w : r.warnings) std::cerr << "vibid: warning: " << w << "\n";
}

}  // namespace

void RegisterFrfEstimate(CLI::App& app) {
  const auto [cmd, args] = AddCommand<FrfEstimateArgs>(app, "frf-estimate", kFrfEstimateHelp, Run);
  cmd->add_option("recording", args->input, "Recording CSV (t_s column first)")->required();
  AddEstimationOptions(cmd, args->est, true, "receptance");
  cmd->add_option("-o,--output", args->output,
                  "Output FRF.csv or FRF.uff (UFF58); default: CSV on stdout");
  cmd->add_option("--reference-node", args->reference_node,
                  "UFF58 node number of the force (default: responses are nodes 1..n, the force "
                  "the last of them)");
}

void AddModeOptions(CLI::App* cmd, ModeArgs& m) {
  cmd->add_option("--method", m.method,
                  "lscf (pLSCF poles over model orders, stabilization diagram, automatic pole "
                  "choice, residues by\n"
                  "least squares), lsce (the same with time-domain complex exponentials), fit "
                  "(multi-mode least\n"
                  "squares started from the peaks), peaks (Eq. 10 from peak amplitudes)")
      ->capture_default_str();
  cmd->add_option(
      "--orders", m.orders,
      "lscf/lsce model orders MIN:MAX[:STEP] (default: 4 up to the highest order the\n"
      "band's frequency lines carry, in steps of 2: a quarter of the lines, or up to "
      "16 where\nthe fit allows, never above 48; the output's stabilization line names the "
      "orders run)");
  cmd->add_option("--driving-point", m.driving_point,
                  "Response measured at the hammer point: its column name or 1-based index\n"
                  "(default: found from the data, the one response whose modal constants are "
                  "positive in\nevery mode; one the data contradict is refused, naming the one "
                  "that fits)");
  cmd->add_option("--fmin-hz", m.options.peaks.freq_min_hz,
                  "Lowest frequency searched for peaks (Hz)")
      ->check(NonNegativeNumber());
  cmd->add_option("--fmax-hz", m.options.peaks.freq_max_hz,
                  "Highest frequency searched for peaks (Hz; 0: all)")
      ->check(NonNegativeNumber());
  cmd->add_option("--threshold", m.options.peaks.threshold_fraction,
                  "Ignore peaks below this fraction of the largest")
      ->capture_default_str();
  cmd->add_option("--max-modes", m.options.peaks.max_peaks, "Keep the largest N peaks (0: all)");
}

void RegisterModes(CLI::App& app) {
  const auto [cmd, args] = AddCommand<ModesArgs>(app, "modes", kModesHelp, Run);
  cmd->add_option("inputs", args->inputs, "FRF.csv | FRF.uff | REC.csv ...")->required();
  AddEstimationOptions(cmd, args->est, false, "receptance");
  AddModeOptions(cmd, args->modes);
  cmd->add_flag("--json", args->json,
                "JSON output: {\"modes\": [{omega_rad_s, freq_hz, zeta, ratio, shape}], ...}");
  cmd->add_option("-o,--output", args->output, "Write the result here instead of stdout");
}

}  // namespace vibid::cli
