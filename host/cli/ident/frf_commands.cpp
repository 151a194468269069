// `vibid frf-estimate` and `vibid modes`.
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "cli_support.hpp"
#include "common/command.hpp"
#include "common/option_text.hpp"
#include "common/solver_json.hpp"
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
  EmitOutput(ident::FormatFrfForPath(e.frf, a.output, ref), a.output);
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

std::string ModesJson(const ModesArgs& a, const ident::Frf& frf, const ident::ModeIdentification& r,
                      const std::vector<std::string>& notes) {
  nlohmann::json j = ModesToJson(r.modes);
  j["method"] = a.modes.method;
  j["responses"] = frf.response_names;
  j["warnings"] = r.warnings;
  j["notes"] = notes;
  if (r.has_diagram) j["stabilization"] = DiagramToJson(r.diagram);
  if (r.fitted) {
    j["summary"] = SolverSummaryJson(r.fit.summary);
    j["fit_band_hz"] = {r.fit.freq_min_hz, r.fit.freq_max_hz};
    j["rms_relative_error"] = r.fit.rms_relative_error;
  }
  return j.dump(2) + "\n";
}

std::string ModesText(const ident::ModeIdentification& r) {
  std::ostringstream out;
  out << ModesTable(r.modes);
  if (r.has_diagram) {
    out << "stabilization diagram: " << ident::PoleMethodName(r.diagram.method) << ", orders "
        << r.diagram.orders.front() << ".." << r.diagram.orders.back() << ", band "
        << r.diagram.freq_min_hz << ".." << r.diagram.freq_max_hz << " Hz, "
        << r.diagram.poles.size() << " poles, " << r.diagram.selected.size()
        << " chosen; residue fit rms relative misfit " << r.fit.rms_relative_error << "\n";
  } else if (r.fitted) {
    out << "curve fit: " << numerics::TerminationName(r.fit.summary.termination) << ", "
        << r.fit.summary.iterations << " iterations, cost " << r.fit.summary.initial_cost << " -> "
        << r.fit.summary.final_cost << ", rms relative misfit " << r.fit.rms_relative_error << "\n";
  }
  return out.str();
}

void Run(const ModesArgs& a) {
  Require(a.est.kind == "receptance",
          "modes are identified from receptances; leave --kind at its default");
  std::vector<ident::Frf> frfs;
  std::vector<std::string> notes;
  for (const std::string& in : a.inputs) frfs.push_back(LoadOrEstimate(in, a.est, notes));
  const ident::Frf frf = JoinColumns(frfs, a.inputs);
  const ident::ModeIdentification r = RunModes(frf, a.modes);
  EmitOutput(a.json ? ModesJson(a, frf, r, notes) : ModesText(r), a.output);
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
  cmd->add_option("--orders", m.orders, "lscf/lsce model orders MIN:MAX[:STEP] (default 4:48:2)");
  cmd->add_option("--driving-point", m.driving_point,
                  "Response measured at the hammer point: its column name or 1-based index "
                  "(default: the last response)");
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

std::size_t ResolveDrivingPoint(const ident::Frf& frf, const std::string& spec) {
  if (spec.empty()) return frf.responses() - 1;
  for (std::size_t j = 0; j < frf.response_names.size(); ++j) {
    if (frf.response_names[j] == spec) return j;
  }
  const std::optional<long long> index = ParseInteger(spec);
  Require(index && *index >= 1 && static_cast<std::size_t>(*index) <= frf.responses(),
          "--driving-point '" + spec + "' is neither a response name nor an index 1.." +
              std::to_string(frf.responses()));
  return static_cast<std::size_t>(*index - 1);
}

ident::ModeIdentification RunModes(const ident::Frf& receptance, const ModeArgs& m) {
  ident::ModeIdentificationOptions o = m.options;
  o.method = ident::ParseModeMethod(m.method);
  if (!m.orders.empty()) ident::ParseOrders(m.orders, o.stabilization);
  return ident::IdentifyModes(receptance, ResolveDrivingPoint(receptance, m.driving_point), o);
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
