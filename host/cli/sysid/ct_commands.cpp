// vibid tfest, vibid compare, vibid greybox cart: continuous-time models.
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>

#include "cli_support.hpp"
#include "common/command.hpp"
#include "vibid/common/option_text.hpp"
#include "common/solver_json.hpp"
#include "sysid/sysid_cli.hpp"
#include "vibid/common/atomic_file.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/json_file.hpp"
#include "vibid/common/json_keys.hpp"
#include "vibid/model/model_json.hpp"
#include "vibid/model/transfer_function.hpp"
#include "vibid/sysid/continuous.hpp"
#include "vibid/sysid/greybox.hpp"
#include "vibid/sysid/tfest.hpp"

namespace vibid::cli {

namespace {

constexpr const char* kTfestHelp =
    "Continuous-time transfer function num(s)/den(s) (SRIVC start, output-error refinement)";

struct TfestArgs {
  workflow::TfestRequest request;
  bool json = false;
  std::string out;
};

void Run(const TfestArgs& a) {
  const workflow::SysidReport r = workflow::RunTfest(a.request);
  Emit(r.json, r.text, a.json, a.out);
  SayCautions(r.cautions, "the model");
}

constexpr const char* kCompareHelp =
    "Fit of a model's simulated (or k-step predicted) output to a recording: "
    "100(1-|y-yhat|/|y-mean(y)|) %";

struct CompareArgs {
  workflow::CompareRequest request;
  std::string write_sim;
  bool json = false;
};

void Run(const CompareArgs& a) {
  const workflow::CompareReport r = workflow::RunCompare(a.request);
  if (!a.write_sim.empty())
    WriteFileAtomic(a.write_sim, FormatCsv({"t_s", "y", "y_model"}, {r.t_s, r.y, r.y_model}));
  Emit(r.json, r.text, a.json, "");
}

constexpr const char* kGreyboxHelp =
    "Cart track (methods §10): M, B, k (and Bi) of one cart or M1, M2, B1, B2, k (and Bi) of two";

struct GreyboxArgs {
  workflow::GreyboxRequest request;
  bool json = false;
  std::string out;
};

void Run(const GreyboxArgs& a) {
  const workflow::SysidReport r = workflow::RunGreybox(a.request);
  Emit(r.json, r.text, a.json, a.out);
  SayCautions(r.cautions, "the model");
}

}  // namespace

void RegisterTfestCommand(CLI::App& app) {
  const auto [cmd, a] = AddCommand<TfestArgs>(app, "tfest", kTfestHelp, Run);
  AddRecordOptions(*cmd, a->request.record);
  cmd->add_option("--np", a->request.np, "Number of poles")->required()->check(CLI::Range(1, 20));
  cmd->add_option("--nz", a->request.nz, "Number of zeros (< np)")->check(CLI::Range(0, 19));
  cmd->add_option("--ic", a->request.ic,
                  "Initial conditions: zero (record starts at rest) | estimate")
      ->check(CLI::IsMember({"zero", "estimate"}));
  cmd->add_option("--estimate-range", a->request.estimate_range,
                  "Samples FIRST:LAST (LAST excluded) used for estimation");
  cmd->add_option("--validate-range", a->request.validate_range,
                  "Samples FIRST:LAST for a validation fit");
  cmd->add_option("--max-iterations", a->request.max_iterations,
                  "Iteration limit of the output-error search")
      ->check(CLI::Range(1, 100000));
  cmd->add_flag("--json", a->json, "Print the result as JSON");
  cmd->add_option("-o,--out", a->out, "Write the TF (JSON, readable by compare) to this file");
}

void RegisterCompareCommand(CLI::App& app) {
  const auto [cmd, a] = AddCommand<CompareArgs>(app, "compare", kCompareHelp, Run);
  AddRecordOptions(*cmd, a->request.record);
  cmd->add_option("--model", a->request.model,
                  "TF.json (num/den, as tfest and greybox write), a polynomial model (arx/pem -o), "
                  "or a model file "
                  "(M/C/K or topology; the input column is then a force in N, the output a "
                  "displacement in m)")
      ->required();
  cmd->add_option("--input-dof", a->request.input_dof,
                  "Model file: DOF the input force acts on (from 1)")
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--output-dof", a->request.output_dof,
                  "Model file: DOF whose displacement is the output (from 1)")
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--horizon", a->request.horizon,
                  "inf (simulation) or K >= 1 (K-step-ahead prediction)");
  cmd->add_option("--method", a->request.method,
                  "Simulation of a continuous TF: exact (ZOH) | euler | rk4")
      ->check(CLI::IsMember({"exact", "euler", "rk4"}));
  cmd->add_option("--substeps", a->request.substeps, "Integration steps per sample for euler/rk4")
      ->check(CLI::Range(1, 10000));
  cmd->add_option("--ic", a->request.ic,
                  "Initial conditions of a continuous TF: zero | estimate (least squares)")
      ->check(CLI::IsMember({"zero", "estimate"}));
  cmd->add_option("--range", a->request.range, "Samples FIRST:LAST (LAST excluded) to compare on");
  cmd->add_option("--write-sim", a->write_sim, "Write t_s, measured and model output to this CSV");
  cmd->add_flag("--json", a->json, "Print the result as JSON");
}

void RegisterGreyboxCommand(CLI::App& app) {
  auto* group = app.add_subcommand(
      "greybox", "Physical parameters by output error on a first-principle model");
  group->require_subcommand(1);
  const auto [cmd, a] = AddCommand<GreyboxArgs>(*group, "cart", kGreyboxHelp, Run);
  AddRecordOptions(*cmd, a->request.record);
  cmd->add_option("--carts", a->request.carts, "1 (cart 2 pinned) or 2")
      ->check(CLI::IsMember({1, 2}));
  cmd->add_option("--input-kind", a->request.input_kind,
                  "force (N on cart 1) | position (Xi through the first spring, m)")
      ->check(CLI::IsMember({"force", "position"}));
  cmd->add_option("--fix", a->request.fix, "Parameters held fixed, e.g. M=0.57,k=15 (SI units)");
  cmd->add_option("--ic", a->request.ic, "Initial conditions: zero | estimate")
      ->check(CLI::IsMember({"zero", "estimate"}));
  cmd->add_option("--estimate-range", a->request.estimate_range,
                  "Samples FIRST:LAST (LAST excluded) used for estimation");
  cmd->add_flag("--json", a->json, "Print the result as JSON");
  cmd->add_option("-o,--out", a->out,
                  "Write the result (JSON, with num/den readable by compare) to this file");
}

}  // namespace vibid::cli
