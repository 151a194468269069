// `vibid simulate MODEL.json --method euler|rk4|exact --dt-s --t-end-s --force SPEC ...`: time
// response.
#include <string>
#include <vector>

#include "cli_support.hpp"
#include "common/command.hpp"
#include "model/model_commands.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/model/model_json.hpp"
#include "vibid/model/simulate.hpp"

namespace vibid::cli {
namespace {

constexpr const char* kSimulateHelp =
    "Time response of M x'' + C x' + K x = F(t). CSV columns: t_s, x<i>_m, v<i>_m_s, a<i>_m_s2, "
    "f<i>_n.\n"
    "Force SPECs (DOF from 1, amp in N, times in s, frequencies in Hz; t0 defaults to 0):\n"
    "  step:dof=1,amp=5[,t0=0]                  pulse:dof=1,amp=5,width=0.1[,t0=0]\n"
    "  halfsine:dof=2,amp=100,width=0.001[,t0=] sine:dof=2,amp=1,freq_hz=16[,t0=]\n"
    "  chirp:dof=1,amp=1,f0_hz=1,f1_hz=50,t1=10[,t0=]  (linear sweep over t1 seconds)";

struct SimulateArgs {
  std::string model_path;
  std::string method = "rk4";
  double dt_s = 0.0;
  double t_end_s = 0.0;
  std::vector<std::string> forces;
  std::string force_table;
  std::vector<std::string> frictions;
  std::string x0;
  std::string v0;
  std::string output_path;
};

Eigen::VectorXd InitialState(const std::string& text, const char* option, int dofs) {
  if (text.empty()) return {};
  const std::vector<double> values = ParseNumberList(text, option);
  Require(static_cast<int>(values.size()) == dofs,
          std::string(option) + " has " + std::to_string(values.size()) +
              " values, the model has " + std::to_string(dofs) + " DOFs");
  return Eigen::Map<const Eigen::VectorXd>(values.data(), static_cast<Eigen::Index>(values.size()));
}

void Run(const SimulateArgs& a) {
  const model::Model m = model::LoadModel(a.model_path);
  const int n = m.dofs();
  model::SimulationOptions options;
  options.method = model::ParseMethod(a.method);
  options.dt_s = a.dt_s;
  options.t_end_s = a.t_end_s;
  options.x0_m = InitialState(a.x0, "--x0-m", n);
  options.v0_m_s = InitialState(a.v0, "--v0-m-s", n);
  for (const std::string& f : a.frictions) {
    const std::vector<double> mu = ParseNumberList(f, "--friction");
    Require(mu.size() == 2, "--friction '" + f + "': expected mu_static,mu_dynamic");
    options.friction.push_back({mu[0], mu[1]});
  }
  model::ForceInput force;
  for (const std::string& spec : a.forces) force.shapes.push_back(model::ParseForceShape(spec));
  if (!a.force_table.empty()) force.table = model::LoadForceTable(a.force_table, n);
  Require(!force.empty() || options.x0_m.size() > 0 || options.v0_m_s.size() > 0,
          "nothing excites the model: give --force, --force-table, --x0-m or --v0-m-s");

  const model::SimulationResult r = model::Simulate(m, force, options);
  std::vector<std::string> names{"t_s"};
  std::vector<Eigen::VectorXd> columns{r.t_s};
  const auto add = [&](const Eigen::MatrixXd& values, const char* prefix, const char* unit) {
    for (int i = 0; i < n; ++i) {
      names.push_back(prefix + std::to_string(i + 1) + unit);
      columns.push_back(values.col(i));
    }
  };
  add(r.x_m, "x", "_m");
  add(r.v_m_s, "v", "_m_s");
  add(r.a_m_s2, "a", "_m_s2");
  add(r.force_n, "f", "_n");
  EmitOutput(FormatCsv(names, columns), a.output_path);
}

}  // namespace

void RegisterSimulateCommand(CLI::App& app) {
  const auto [cmd, args] = AddCommand<SimulateArgs>(app, "simulate", kSimulateHelp, Run);
  cmd->add_option("model", args->model_path, "Model file (JSON)")->required();
  cmd->add_option("--method", args->method,
                  "euler | rk4 | exact (zero-order hold: exact for forces constant over each step; "
                  "linear only)")
      ->capture_default_str();
  cmd->add_option("--dt-s", args->dt_s, "Time step, s (> 0)")->required();
  cmd->add_option("--t-end-s", args->t_end_s, "Duration, s (> dt)")->required();
  // One value per occurrence, so a SPEC never swallows the model path that follows it.
  cmd->add_option("--force", args->forces, "Force shape SPEC (repeatable; forces add up)")
      ->allow_extra_args(false);
  cmd->add_option("--force-table", args->force_table,
                  "CSV with t_s and f<i>_n columns (N), held from each sample to the next");
  cmd->add_option("--friction", args->frictions,
                  "Coulomb friction mu_static,mu_dynamic (normal force m g): once for every mass, "
                  "or once per DOF")
      ->allow_extra_args(false);
  cmd->add_option("--x0-m", args->x0, "Initial positions, m, comma separated (default 0)");
  cmd->add_option("--v0-m-s", args->v0, "Initial velocities, m/s, comma separated (default 0)");
  cmd->add_option("-o,--output-file", args->output_path, "CSV file to write (default: stdout)");
}

}  // namespace vibid::cli
