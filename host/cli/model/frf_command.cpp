// `vibid frf MODEL.json --input I --output O[,O2] --kind K --f-min-hz --f-max-hz --points N`:
// synthesized FRFs as CSV.
#include <cmath>
#include <complex>
#include <numbers>
#include <string>
#include <vector>

#include "cli_support.hpp"
#include "common/command.hpp"
#include "model/model_commands.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/model/frf.hpp"
#include "vibid/model/model_json.hpp"

namespace vibid::cli {
namespace {

constexpr const char* kFrfHelp =
    "Frequency response of a model, (K - w^2 M + j w C)^-1 for receptance (m/N), times j w for "
    "mobility\n"
    "(m/(N*s)), times -w^2 for accelerance (m/(N*s^2)). CSV: freq_hz, then "
    "re_/im_<kind>_<in>_<out>\n"
    "per output (or mag_ and phase_deg_ with --polar).";

struct FrfArgs {
  std::string model_path;
  int input = 1;
  std::string outputs;
  std::string kind = "receptance";
  double f_min_hz = 0.0;
  double f_max_hz = 0.0;
  int points = 500;
  bool log = false;
  bool polar = false;
  std::string output_path;
};

void Run(const FrfArgs& a) {
  const model::Model m = model::LoadModel(a.model_path);
  const model::FrfKind kind = model::ParseFrfKind(a.kind);
  Require(a.input >= 1 && a.input <= m.dofs(),
          "--input " + std::to_string(a.input) + " is out of range 1.." + std::to_string(m.dofs()));
  const std::vector<int> outputs = ParseDofList(a.outputs, "--output");
  for (const int out : outputs) {
    Require(out < m.dofs(), "--output " + std::to_string(out + 1) + " is out of range 1.." +
                                std::to_string(m.dofs()));
  }
  Require(std::isfinite(a.f_min_hz) && a.f_min_hz >= 0.0, "--f-min-hz must be >= 0");
  Require(std::isfinite(a.f_max_hz) && a.f_max_hz > a.f_min_hz,
          "--f-max-hz must be greater than --f-min-hz");
  Require(a.points >= 2 && a.points <= 10000000, "--points must be between 2 and 10000000");
  Require(!a.log || a.f_min_hz > 0.0, "--log needs --f-min-hz > 0");

  Eigen::VectorXd freq_hz(a.points);
  if (a.log) {
    freq_hz = Eigen::VectorXd::LinSpaced(a.points, std::log10(a.f_min_hz), std::log10(a.f_max_hz));
    freq_hz = freq_hz.unaryExpr([](double e) { return std::pow(10.0, e); });
    freq_hz[0] = a.f_min_hz;  // exact ends, not 10^log10(f)
    freq_hz[a.points - 1] = a.f_max_hz;
  } else {
    freq_hz = Eigen::VectorXd::LinSpaced(a.points, a.f_min_hz, a.f_max_hz);
  }
  const Eigen::VectorXd omega = 2.0 * std::numbers::pi * freq_hz;

  std::vector<std::string> names{"freq_hz"};
  std::vector<Eigen::VectorXd> columns{freq_hz};
  const std::string kind_name(model::FrfKindName(kind));
  for (const int out : outputs) {
    const Eigen::VectorXcd h = model::Frf(m, a.input - 1, out, kind, omega);
    const std::string suffix =
        kind_name + "_" + std::to_string(a.input) + "_" + std::to_string(out + 1);
    if (a.polar) {
      names.push_back("mag_" + suffix);
      names.push_back("phase_deg_" + suffix);
      columns.push_back(h.cwiseAbs());
      columns.push_back(h.unaryExpr([](std::complex<double> z) {
                           return std::arg(z) * 180.0 / std::numbers::pi;
                         }).real());
    } else {
      names.push_back("re_" + suffix);
      names.push_back("im_" + suffix);
      columns.push_back(h.real());
      columns.push_back(h.imag());
    }
  }
  EmitOutput(FormatCsv(names, columns), a.output_path);
}

}  // namespace

void RegisterFrfCommand(CLI::App& app) {
  const auto [cmd, args] = AddCommand<FrfArgs>(app, "frf", kFrfHelp, Run);
  cmd->add_option("model", args->model_path, "Model file (JSON)")->required();
  cmd->add_option("--input", args->input, "DOF the force acts on (from 1)")->required();
  cmd->add_option("--output", args->outputs, "Response DOF(s), comma separated (from 1)")
      ->required();
  cmd->add_option("--kind", args->kind, "receptance | mobility | accelerance")
      ->capture_default_str();
  cmd->add_option("--f-min-hz", args->f_min_hz, "First frequency, Hz (>= 0)")->required();
  cmd->add_option("--f-max-hz", args->f_max_hz, "Last frequency, Hz")->required();
  cmd->add_option("--points", args->points, "Number of frequencies")->capture_default_str();
  cmd->add_flag("--log", args->log, "Logarithmic frequency spacing (needs --f-min-hz > 0)");
  cmd->add_flag("--polar", args->polar,
                "Magnitude and phase (degrees) instead of real and imaginary parts");
  cmd->add_option("-o,--output-file", args->output_path, "CSV file to write (default: stdout)");
}

}  // namespace vibid::cli
