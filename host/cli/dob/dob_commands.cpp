// `vibid dob design | run | compare | start | stop`: observer design from a model file, replay of
// the board's fixed-point observer (or the double design) on a recording, agreement with a measured
// force; start and stop act on the board and live with the device commands.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "cli_support.hpp"
#include "commands.hpp"
#include "common/command.hpp"
#include "device/device_commands.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/json_file.hpp"
#include "vibid/common/verdict.hpp"
#include "vibid/device/calibration_builder.hpp"
#include "vibid/device/calibration_upload.hpp"
#include "vibid/dob/compare.hpp"
#include "vibid/dob/design.hpp"
#include "vibid/dob/design_json.hpp"
#include "vibid/dob/lowpass.hpp"
#include "vibid/dob/model_plant.hpp"
#include "vibid/model/model_json.hpp"
#include "vibid/workflow/observer_design.hpp"

namespace vibid::cli {
namespace {

constexpr const char* kDesignHelp = "Design the observer for a model and quantize it for the board";

struct DesignArgs {
  std::string model_path;
  std::string out;
  std::string sensors;
  bool json = false;
  bool force_given = false;
  bool sensor_given = false;
  bool accept_flagged = false;
  bool input_dof_given = false;
  bool output_dof_given = false;
  bool sensor_kind_given = false;
  workflow::ObserverDesignRequest request;
};

void Run(const DesignArgs& a) {
  // The model's verdict first: a flagged model is refused before anything else is read or said.
  const model::ModelFile model = model::LoadModelFile(a.model_path);
  RequireUsable(model.verdict, a.accept_flagged, "model file " + a.model_path, "dob design",
                "--accept-flagged");
  if (model.verdict.level != VerdictLevel::kOk)
    std::cerr << "vibid: " << (model.verdict.Flagged() ? "warning: " : "note: ") << a.model_path
              << ": " << FormatVerdict(model.verdict) << "\n";
  workflow::ObserverDesignRequest request = a.request;
  // The full scales are the sensors' when a sensors file is given: the ones `cal upload` takes.
  if (!a.sensors.empty()) {
    const device::SensorSet sensors = device::SensorsFromJson(ReadJsonFile(a.sensors), a.sensors);
    // The observer's mass is the load cell's, as `cal upload` with these sensors requires, on a
    // chain of any length; options given keep their word (cal upload then judges them).
    const std::string placed =
        device::PlaceObserver(sensors, request.input_dof, a.input_dof_given, request.output_dof,
                              a.output_dof_given, request.sensor, a.sensor_kind_given);
    const std::string took = device::TakeSensorFullScales(
        sensors, request.input_dof, request.output_dof, request.sensor, request.force_fs_n,
        a.force_given, request.sensor_fs, a.sensor_given);
    const std::string said = placed + (placed.empty() || took.empty() ? "" : ", ") + took;
    if (!said.empty()) std::cerr << "vibid: " << said << " (" << a.sensors << ")\n";
  }
  const dob::DobDesign design = workflow::DesignObserverFor(model.model, request);
  // Said of a design made, never above a refusal.
  if (a.sensors.empty() && !a.force_given)
    std::cerr << "vibid: note: force full scale " << request.force_fs_n
              << " N, the default: give --sensors SENSORS.json to take the load cell's, which "
                 "cal upload requires\n";
  const std::string text = dob::DesignToJson(design).dump(2) + "\n";
  EmitOutput(text, a.out);
  if (!a.out.empty() && a.out != "-")
    std::cout << (a.json ? text : workflow::DesignSummary(design));
}

constexpr const char* kRunHelp =
    "Replay the observer on a recording; adds d_hat_n, d_hat_q31 (fixed point) and d_hat_lp_n";

struct RunArgs {
  std::string recording;
  std::string design;
  std::string force;
  std::string response;
  bool fixed = false;
  bool use_float = false;
  double lowpass_hz = 0.0;
  int lowpass_order = 4;
  std::string name = "d_hat";
  std::string verify;
  std::string out;
};

// Compares the replay with the board's own output, sample for sample: the fixed-point kernel is
// the same code on both sides, so any difference is a fault (wrong calibration, lost samples).
void VerifyAgainstBoard(const Recording& rec, const std::string& column,
                        const std::vector<std::int32_t>& replay_q31) {
  const Eigen::VectorXd board = rec.Signal(ParseColumnSpec(column));
  std::size_t mismatches = 0;
  Eigen::Index first = -1;
  for (Eigen::Index i = 0; i < board.size(); ++i) {
    if (board[i] != static_cast<double>(replay_q31[static_cast<std::size_t>(i)])) {
      if (mismatches++ == 0) first = i;
    }
  }
  if (mismatches > 0) {
    throw NumericalError("the board's " + column + " differs from the replay in " +
                         std::to_string(mismatches) + " of " + std::to_string(board.size()) +
                         " samples (first at row " + std::to_string(first + 1) + ": board " +
                         std::to_string(static_cast<long long>(board[first])) + ", replay " +
                         std::to_string(replay_q31[static_cast<std::size_t>(first)]) + ")");
  }
  std::cerr << "vibid: bit-exact: " << board.size() << " samples of " << column
            << " equal the replay\n";
}

void Run(const RunArgs& a) {
  const Recording rec = LoadRecording(a.recording);
  const dob::ObserverFile f = dob::ObserverFromJson(ReadJsonFile(a.design), a.design);
  Require(std::abs(rec.fs_hz - f.fs_hz) <= 1e-6 * f.fs_hz,
          a.recording + " is sampled at " + std::to_string(rec.fs_hz) +
              " Hz but the observer was designed for " + std::to_string(f.fs_hz) + " Hz");
  const std::vector<ColumnSpec> responses = ParseColumnList(a.response);
  const std::size_t sensors = f.paths.size() - 1;
  if (responses.size() != sensors) {
    std::string want;
    for (std::size_t i = 0; i < sensors; ++i) {
      want += (i ? ", " : "") + std::string(dob::InputKindName(f.paths[i].kind)) + " of m" +
              std::to_string(f.paths[i].dof + 1);
    }
    throw InputError("the observer takes " + std::to_string(sensors) + " response column(s) (" +
                     want + "), got " + std::to_string(responses.size()));
  }
  Require(!a.name.empty() && a.name.find(',') == std::string::npos,
          "--name must be a non-empty column stem");
  const std::string out_n = a.name + "_n", out_lp = a.name + "_lp_n", out_q31 = a.name + "_q31";
  for (const std::string& name : {out_n, out_lp, out_q31}) {
    Require(!rec.table.Has(name),
            a.recording + " already has a column '" + name + "' (choose another --name)");
  }
  Require(a.verify.empty() || !a.use_float,
          "--verify compares the fixed-point replay; it does not go with --float");
  std::vector<Eigen::VectorXd> inputs;
  for (const ColumnSpec& c : responses) inputs.push_back(rec.Signal(c));
  inputs.push_back(rec.Signal(ParseColumnSpec(a.force)));
  for (const Eigen::VectorXd& x : inputs)
    Require(x.allFinite(), a.recording + ": an input column has non-finite values");
  if (a.lowpass_hz != 0.0) {
    Require(a.lowpass_hz < rec.fs_hz / 2.0,
            "--lowpass-hz must lie below fs/2 = " + std::to_string(rec.fs_hz / 2.0) + " Hz");
  }
  Eigen::VectorXd d_hat;
  Eigen::VectorXd d_hat_q31;
  if (a.use_float) {
    d_hat = dob::RunFloat(f.paths, inputs);
  } else {
    const dob::FixedRun run = dob::RunFixed(f.description, inputs);
    d_hat = run.d_hat_n;
    d_hat_q31 = Eigen::Map<const Eigen::Matrix<std::int32_t, Eigen::Dynamic, 1>>(
                    run.d_hat_q31.data(), d_hat.size())
                    .cast<double>();
    if (!a.verify.empty()) VerifyAgainstBoard(rec, a.verify, run.d_hat_q31);
    if (run.saturations > 0) {
      std::cerr << "vibid: warning: the fixed-point observer saturated " << run.saturations
                << " times (inputs beyond the design's full scale)\n";
    }
  }
  std::vector<std::string> names = rec.table.names;
  std::vector<Eigen::VectorXd> columns = rec.table.columns;
  names.push_back(out_n);
  columns.push_back(d_hat);
  if (d_hat_q31.size() > 0) {
    names.push_back(out_q31);
    columns.push_back(d_hat_q31);
  }
  if (a.lowpass_hz != 0.0) {
    names.push_back(out_lp);
    columns.push_back(
        dob::FiltFilt(dob::ButterworthLowpass(a.lowpass_order, a.lowpass_hz, rec.fs_hz), d_hat));
  }
  EmitOutput(FormatCsv(names, columns), a.out);
}

constexpr const char* kDobCompareHelp = "Agreement of an estimated and a measured disturbance";

struct CompareArgs {
  std::string recording;
  std::string estimate;
  std::string measured;
  double skip_s = 0.0;
  double max_delay_s = 0.0;
  bool json = false;
  std::string out;
};

void Run(const CompareArgs& a) {
  const Recording rec = LoadRecording(a.recording);
  const Eigen::VectorXd e = rec.Signal(ParseColumnSpec(a.estimate));
  const Eigen::VectorXd m = rec.Signal(ParseColumnSpec(a.measured));
  const auto skip = static_cast<Eigen::Index>(std::llround(a.skip_s * rec.fs_hz));
  Require(2 * skip + 2 <= e.size(),
          "--skip-s " + std::to_string(a.skip_s) + " s at both ends leaves fewer than 2 samples");
  const Eigen::Index n = e.size() - 2 * skip;
  const dob::Agreement g =
      dob::CompareSignals(e.segment(skip, n), m.segment(skip, n), rec.fs_hz, a.max_delay_s);
  nlohmann::json j = {{"fit_percent", g.fit_percent},
                      {"correlation", g.correlation},
                      {"delay_s", g.delay_s},
                      {"rmse_n", g.rmse_n}};
  if (a.json) {
    EmitOutput(j.dump(2) + "\n", a.out);
  } else {
    char text[256];
    std::snprintf(text, sizeof(text), "fit %.3f %%\ncorrelation %.6f\ndelay %.6g s\nrmse %.6g N\n",
                  g.fit_percent, g.correlation, g.delay_s, g.rmse_n);
    EmitOutput(text, a.out);
  }
}

void RegisterDobDesignCommand(CLI::App& dob) {
  const auto [cmd, a] = AddCommand<DesignArgs>(dob, "design", kDesignHelp, Run);
  cmd->add_option("model", a->model_path, "Model file (JSON)")->required();
  cmd->add_flag("--accept-flagged", a->accept_flagged,
                "Design for a model whose verdict is flagged (refused otherwise, exit 6)");
  cmd->add_option("--N", a->request.order, "Order of Q (>= 1)")->capture_default_str();
  cmd->add_option("--r", a->request.relative_degree,
                  "Relative degree of Q (0 <= N - r, r >= that of G_A)")
      ->capture_default_str();
  cmd->add_option("--tau-s", a->request.tau_s, "Time constant of Q, s (cut-off 1/tau rad/s)")
      ->check(PositiveNumber())
      ->capture_default_str();
  cmd->add_option("--fs-hz", a->request.fs_hz, "Board sample rate, Hz")
      ->check(PositiveNumber())
      ->capture_default_str();
  cmd->add_option("--input-dof", a->request.input_dof,
                  "Mass the force (and the disturbance) acts on, from 1 (default: load cell "
                  "force1's mass in --sensors, else 2)")
      ->each([given = &a->input_dof_given](const std::string&) { *given = true; });
  cmd->add_option("--output-dof", a->request.output_dof,
                  "Mass whose sensor feeds the SISO form, from 1 (default: as --input-dof)")
      ->each([given = &a->output_dof_given](const std::string&) { *given = true; });
  cmd->add_option("--sensor", a->request.sensor,
                  "Sensor: disp, vel or acc (default: the encoder on that mass in --sensors, "
                  "else its accelerometer; without --sensors disp)")
      ->check(CLI::IsMember({"disp", "vel", "acc"}))
      ->each([given = &a->sensor_kind_given](const std::string&) { *given = true; });
  cmd->add_option("--form", a->request.form,
                  "siso: Q G_A^-1 y - Q u; mimo: Q[M x'' + C x' + K x - F]")
      ->check(CLI::IsMember({"siso", "mimo"}))
      ->capture_default_str();
  cmd->add_option("--discretize", a->request.discretize, "tustin (pre-warped at 1/tau) or zoh")
      ->check(CLI::IsMember({"tustin", "zoh"}))
      ->capture_default_str();
  cmd->add_option("--prototype", a->request.prototype, "Q polynomial: butterworth or binomial")
      ->check(CLI::IsMember({"butterworth", "binomial"}))
      ->capture_default_str();
  cmd->add_option("--leak-hz", a->request.leak_hz,
                  "Corner of the leaky integrators for vel/acc sensors, Hz")
      ->check(PositiveNumber())
      ->capture_default_str();
  cmd->add_option("--sensors", a->sensors,
                  "Sensors file (as for cal upload): the force and sensor full scales are its "
                  "load cell's on --input-dof and its --sensor's on --output-dof");
  cmd->add_option("--force-fs-n", a->request.force_fs_n,
                  "Force full scale, N (default: the load cell's in --sensors, else 100)")
      ->check(PositiveNumber())
      ->each([given = &a->force_given](const std::string&) { *given = true; });
  cmd->add_option("--sensor-fs", a->request.sensor_fs,
                  "Sensor full scale, SI (default: the sensor's in --sensors, else 0: 0.05 m, "
                  "1 m/s or 50 m/s^2)")
      ->check(NonNegativeNumber())
      ->each([given = &a->sensor_given](const std::string&) { *given = true; });
  cmd->add_option("--output-fs-n", a->request.output_fs_n,
                  "Full scale of d_hat, N (0: twice the force full scale)")
      ->check(NonNegativeNumber())
      ->capture_default_str();
  cmd->add_option("-o,--output", a->out, "Design file to write (default: stdout)");
  cmd->add_flag("--json", a->json, "Print the design JSON on stdout even when writing a file");
}

void RegisterDobRunCommand(CLI::App& dob) {
  const auto [cmd, a] = AddCommand<RunArgs>(dob, "run", kRunHelp, Run);
  cmd->add_option("recording", a->recording, "Recording (CSV, t_s column)")->required();
  cmd->add_option("--design", a->design, "Design file from `vibid dob design`")->required();
  cmd->add_option("--force", a->force, "Measured force column (NAME, NAME:UNIT or NAME*FACTOR)")
      ->required();
  cmd->add_option("--response", a->response,
                  "Sensor column(s), comma separated, in the design's input order")
      ->required();
  auto* fixed_flag = cmd->add_flag("--fixed", a->fixed,
                                   "Bit-exact replay of the board's fixed-point filter (default)");
  cmd->add_flag("--float", a->use_float, "The double-precision design instead")
      ->excludes(fixed_flag);
  cmd->add_option("--lowpass-hz", a->lowpass_hz,
                  "Also write NAME_lp_n: zero-phase Butterworth low-pass at this cut-off, Hz")
      ->check(PositiveNumber());
  cmd->add_option("--lowpass-order", a->lowpass_order, "Order of that low-pass")
      ->check(CLI::Range(1, 16))
      ->capture_default_str();
  cmd->add_option("--name", a->name, "Stem of the added columns: NAME_n, NAME_q31, NAME_lp_n")
      ->capture_default_str();
  cmd->add_option("--verify", a->verify,
                  "Board output column (e.g. d_hat_q31 of `vibid acquire`): fail unless the replay "
                  "equals it bit for bit");
  cmd->add_option("-o,--output", a->out, "CSV to write (default: stdout)");
}

void RegisterDobCompareCommand(CLI::App& dob) {
  const auto [cmd, a] = AddCommand<CompareArgs>(dob, "compare", kDobCompareHelp, Run);
  cmd->add_option("recording", a->recording, "CSV with both columns (e.g. the output of `dob run`)")
      ->required();
  cmd->add_option("--estimate", a->estimate, "Estimated force column")->required();
  cmd->add_option("--measured", a->measured, "Measured force column")->required();
  cmd->add_option("--skip-s", a->skip_s, "Seconds left out at each end (start-up, filter edges)")
      ->check(NonNegativeNumber())
      ->capture_default_str();
  cmd->add_option("--max-delay-s", a->max_delay_s,
                  "Largest lag searched (0: a tenth of the record)")
      ->check(NonNegativeNumber())
      ->capture_default_str();
  cmd->add_flag("--json", a->json, "JSON: fit_percent, correlation, delay_s, rmse_n");
  cmd->add_option("-o,--output", a->out, "File to write (default: stdout)");
}

}  // namespace

void RegisterDobCommands(CLI::App& app, const GlobalOptions& globals) {
  CLI::App* dob = app.add_subcommand("dob", "Disturbance observer: design, replay, compare");
  dob->require_subcommand(1);
  RegisterDobDesignCommand(*dob);
  RegisterDobRunCommand(*dob);
  RegisterDobCompareCommand(*dob);
  RegisterDobDeviceCommands(*dob, globals);
}

}  // namespace vibid::cli
