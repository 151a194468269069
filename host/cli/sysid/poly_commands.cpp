// vibid arx, vibid pem: discrete-time polynomial models.
#include <limits>
#include <optional>
#include <sstream>

#include "cli_support.hpp"
#include "common/command.hpp"
#include "vibid/common/option_text.hpp"
#include "common/solver_json.hpp"
#include "sysid/sysid_cli.hpp"
#include "vibid/common/error.hpp"
#include "vibid/sysid/continuous.hpp"
#include "vibid/sysid/pem.hpp"
#include "vibid/numerics/polynomial.hpp"

namespace vibid::cli {

namespace {

struct PolyArgs {
  bool json = false;
  std::string out;
};

void AddPolyOptions(CLI::App& cmd, workflow::PolyRequest& r, PolyArgs& a) {
  AddRecordOptions(cmd, r.record);
  cmd.add_option("--estimate-range", r.estimate_range,
                 "Samples FIRST:LAST (LAST excluded) used for estimation");
  cmd.add_option("--validate-range", r.validate_range,
                 "Samples FIRST:LAST for a validation fit (simulation)");
  cmd.add_flag("--d2c", r.d2c,
               "Also give the continuous-time equivalent (ZOH inverse, needs nk <= 1)");
  cmd.add_flag("--json", a.json, "Print the result as JSON");
  cmd.add_option("-o,--out", a.out, "Write the model (JSON) to this file");
}

constexpr const char* kArxHelp =
    "ARX model A(q)y = B(q)u + e by least squares (QR); coefficients in q^-1";

struct ArxArgs {
  workflow::ArxRequest request;
  PolyArgs poly;
};

void Run(const ArxArgs& a) {
  const workflow::SysidReport r = workflow::RunArx(a.request);
  Emit(r.json, r.text, a.poly.json, a.poly.out);
  SayCautions(r.cautions, "the model");
}

constexpr const char* kPemHelp =
    "Prediction-error model (arx, armax, oe, bj) by Levenberg-Marquardt";

struct PemArgs {
  workflow::PemRequest request;
  PolyArgs poly;
};

void Run(const PemArgs& a) {
  const workflow::SysidReport r = workflow::RunPem(a.request);
  Emit(r.json, r.text, a.poly.json, a.poly.out);
  SayCautions(r.cautions, "the model");
}

}  // namespace

void RegisterArxCommand(CLI::App& app) {
  const auto [cmd, a] = AddCommand<ArxArgs>(app, "arx", kArxHelp, Run);
  AddPolyOptions(*cmd, a->request.poly, a->poly);
  cmd->add_option("--na", a->request.na, "Order of A")->check(CLI::NonNegativeNumber);
  cmd->add_option("--nb", a->request.nb, "Number of B coefficients")->check(CLI::PositiveNumber);
  cmd->add_option("--nk", a->request.nk, "Input delay in samples (MATLAB convention; default 1)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--select", a->request.select,
                  "Choose na = nb by aic|fpe over 1..--max-order instead of --na/--nb")
      ->check(CLI::IsMember({"aic", "fpe"}));
  cmd->add_option("--max-order", a->request.max_order, "Largest order tried by --select")
      ->check(CLI::Range(1, 200));
}

void RegisterPemCommand(CLI::App& app) {
  const auto [cmd, a] = AddCommand<PemArgs>(app, "pem", kPemHelp, Run);
  AddPolyOptions(*cmd, a->request.poly, a->poly);
  cmd->add_option("--structure", a->request.structure, "arx | armax | oe | bj")
      ->required()
      ->check(CLI::IsMember({"arx", "armax", "oe", "bj"}));
  cmd->add_option("--orders", a->request.orders,
                  "Orders as NAME=N pairs (na,nb,nc,nd,nf,nk; nk defaults to 1) or MATLAB's "
                  "vector: arx na,nb,nk; "
                  "armax na,nb,nc,nk; oe nb,nf,nk; bj nb,nc,nd,nf,nk")
      ->required();
  cmd->add_option("--max-iterations", a->request.max_iterations, "Iteration limit of the search")
      ->check(CLI::Range(1, 100000));
}

}  // namespace vibid::cli
