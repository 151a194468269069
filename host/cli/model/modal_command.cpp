// `vibid modal MODEL.json [--json] [-o FILE]`: natural frequencies, damping and mode shapes.
#include <cmath>
#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "common/command.hpp"
#include "model/model_commands.hpp"
#include "vibid/model/modal.hpp"
#include "vibid/model/model_json.hpp"

namespace vibid::cli {
namespace {

constexpr const char* kModalHelp =
    "Modal analysis of a model: natural frequencies (Hz, rad/s), damping ratios and "
    "mass-normalised mode\n"
    "shapes (1/sqrt(kg)), sorted by frequency; for 2 or more DOFs the shape ratio a1/a2.";

struct ModalArgs {
  std::string model_path;
  bool json = false;
  std::string output;
};

std::string Format(const char* format, double value) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, value);
  return buf;
}

std::string Table(const model::ModalResult& r) {
  const int n = r.size();
  std::string out =
      "damping: " + std::string(model::DampingKindName(r.damping)) +
      (r.damping == model::DampingKind::kGeneral ? " (zeta from complex eigenvalues)" : "") + "\n";
  out += "mode   freq_hz      omega_rad_s  zeta        ";
  if (n >= 2) out += "ratio_a1_a2  ";
  out += "shape (mass-normalised, 1/sqrt(kg))\n";
  for (int i = 0; i < n; ++i) {
    out += Format("%-6.0f ", i + 1.0) + Format("%-12.6g ", r.freq_hz[i]) +
           Format("%-12.6g ", r.omega_rad_s[i]) + Format("%-11.5g ", r.zeta[i]);
    if (n >= 2) out += Format("%-12.6g ", r.ratio[i]);
    for (int j = 0; j < n; ++j) out += Format(j == 0 ? "%.6g" : " %.6g", r.shapes(j, i));
    out += "\n";
  }
  return out;
}

nlohmann::json Json(const model::ModalResult& r) {
  nlohmann::json modes = nlohmann::json::array();
  for (int i = 0; i < r.size(); ++i) {
    nlohmann::json shape = nlohmann::json::array();
    for (Eigen::Index j = 0; j < r.shapes.rows(); ++j) shape.push_back(r.shapes(j, i));
    modes.push_back(
        {{"omega_rad_s", r.omega_rad_s[i]},
         {"freq_hz", r.freq_hz[i]},
         {"zeta", r.zeta[i]},
         {"shape", shape},
         // JSON has no NaN: a 1-DOF model has no ratio.
         {"ratio", std::isnan(r.ratio[i]) ? nlohmann::json(nullptr) : nlohmann::json(r.ratio[i])}});
  }
  return {{"modes", modes}, {"damping", model::DampingKindName(r.damping)}};
}

void Run(const ModalArgs& a) {
  const model::ModalResult r = model::Modal(model::LoadModel(a.model_path));
  EmitOutput(a.json ? Json(r).dump(2) + "\n" : Table(r), a.output);
}

}  // namespace

void RegisterModalCommand(CLI::App& app) {
  const auto [cmd, args] = AddCommand<ModalArgs>(app, "modal", kModalHelp, Run);
  cmd->add_option("model", args->model_path,
                  "Model file (JSON: chain, cart or M/K/C matrices in kg, N/m, N*s/m)")
      ->required();
  cmd->add_flag("--json", args->json,
                "Print {\"modes\": [{\"omega_rad_s\", \"freq_hz\", \"zeta\", \"shape\", "
                "\"ratio\"}, ...]} instead of a table");
  cmd->add_option("-o,--output", args->output, "Write to this file instead of stdout");
}

}  // namespace vibid::cli
