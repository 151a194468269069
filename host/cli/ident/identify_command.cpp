// `vibid identify`: the whole chain from hammer recordings to an updated model file.
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "cli_support.hpp"
#include "common/command.hpp"
#include "ident_commands.hpp"
#include "vibid/common/atomic_file.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/json_file.hpp"
#include "vibid/common/verdict.hpp"
#include "vibid/model/model_json.hpp"
#include "vibid/workflow/identify_run.hpp"

namespace vibid::cli {

namespace {

constexpr const char* kIdentifyHelp =
    "The whole identification. Without --mass-test: masses, springs and dampers of the chain "
    "fitted to the\n"
    "modes of the hammer tests of the assembled chain (--modal-test REC, hammer at the driving "
    "point; shapes\n"
    "scaled to unit modal mass by the driving-point residues; fewer modes than masses: the "
    "nominal model as a\n"
    "prior). With --mass-test POS=REC: effective masses from 1-DOF hammer tests, stiffness and "
    "damping from\n"
    "the modes with them, the one-test fit beside. Writes the updated chain model and prints the "
    "validation\n"
    "table (nominal, updated, test) and the verdict: ok, caution (exit 0, said and carried in "
    "the file) or\n"
    "flagged (an update that fits its test worse than the nominal: exit 6 and no -o unless "
    "--accept-flagged).";

struct IdentifyArgs {
  std::string nominal;
  std::vector<std::string> mass_tests;  ///< POS=REC.csv, parsed when the command runs.
  std::string output;
  std::string report;
  bool accept_flagged = false;
  workflow::IdentifyRequest request = workflow::DefaultIdentifyRequest();
};

void Run(const IdentifyArgs& a) {
  const model::Model nominal = model::LoadModel(a.nominal);
  workflow::IdentifyRequest request = a.request;
  for (const std::string& t : a.mass_tests)
    request.mass_tests.push_back(workflow::ParseMassTest(t));
  const workflow::IdentifyRun run = workflow::RunIdentify(nominal, request);
  for (const auto& m : run.messages)
    std::cerr << (m.warning ? "vibid: warning: " : "vibid: note: ") << m.text << "\n";

  const auto n = static_cast<std::size_t>(nominal.dofs());
  const std::string table = workflow::ValidationText(run);
  if (!a.report.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(a.report, ec);
    Require(!ec && std::filesystem::is_directory(a.report),
            "--report: cannot create directory '" + a.report + "'");
    const std::filesystem::path dir(a.report);
    WriteFileAtomic((dir / "validation.txt").string(), table);
    WriteJsonFile((dir / "report.json").string(), workflow::IdentifyReportJson(run, n));
    WriteFileAtomic((dir / "frf_overlay.csv").string(), workflow::FrfOverlayCsv(run, nominal));
  }
  std::cout << table;
  for (const auto& w : run.result.warnings) std::cerr << "vibid: warning: " << w << "\n";
  // The verdict is the table's last line: a flagged result writes no model unless accepted
  // (FlaggedError, its own exit code), a caution is said and carried in the file.
  const Verdict& v = run.result.verdict;
  workflow::WriteUpdatedModel(run, n, a.output, a.accept_flagged, "--accept-flagged");
  if (v.Flagged())
    std::cerr << "vibid: warning: wrote " << a.output
              << " although flagged (--accept-flagged); the file carries the verdict, and dob "
                 "design, report and cal upload refuse it unless given --accept-flagged too\n";
}

}  // namespace

void RegisterIdentify(CLI::App& app) {
  const auto [cmd, a] = AddCommand<IdentifyArgs>(app, "identify", kIdentifyHelp, Run);
  cmd->add_option("--nominal", a->nominal, "Nominal model file (JSON; a chain)")->required();
  cmd->add_option("--mass-test", a->mass_tests,
                  "POS=REC.csv: mass POS (from 1) alone on its spring, hammer test");
  cmd->add_option(
      "--mass-spring", a->request.mass_springs,
      "POS=K: spring (N/m) of that mass test, when it is not the nominal chain spring of POS;\n"
      "POS=fit: not known, fitted with the mass");
  cmd->add_option("--modal-test", a->request.modal_tests,
                  "REC.csv: hammer test of the chain; repeat for several tests")
      ->required();
  cmd->add_option("--force", a->request.estimation.force, "Force column in every recording")
      ->capture_default_str();
  cmd->add_option("--mass-response", a->request.mass_response,
                  "Response column of the mass tests: one for all, or one per --mass-test in order "
                  "(comma separated); default accP_m_s2 for the test of mass P, as acquire names "
                  "it");
  cmd->add_option("--modal-responses", a->request.modal_responses,
                  "Response columns of the modal tests, one per mass in order (accelerometers "
                  "and encoders may be mixed: acc1_m_s2,acc2_m_s2,x1_m); default acc1_m_s2,"
                  "acc2_m_s2 for 1 or 2 masses, as acquire names them");
  cmd->add_option("--sensor", a->request.estimation.sensor,
                  "What the response channels measure: acc, vel or disp, for all or one per "
                  "response (acc,acc,disp); default: each as its unit says (acc1_m_s2, x1_m, "
                  "COLUMN:mm), acceleration when it says none");
  cmd->add_option("--estimator", a->request.estimation.estimator, "FRF estimator: h1, h2, hv")
      ->capture_default_str();
  cmd->add_flag(
      "--welch", a->request.estimation.welch,
      "Welch averaging even for recordings whose force looks like hammer hits (default: per-hit\n"
      "records for hammer tests, Welch for random/periodic excitation, decided per recording)");
  cmd->add_option("--exp-window", a->request.estimation.impact_options.exp_window_end,
                  "Exponential window value at the end of each hit record (0: none); damping is "
                  "corrected for it")
      ->check(NonNegativeNumber());
  cmd->add_option("--record-s", a->request.estimation.impact_options.record_s,
                  "Length of each hit's record, s (default: the shortest hit spacing)")
      ->check(NonNegativeNumber());
  cmd->add_option("--trigger", a->request.estimation.impact_options.trigger_fraction,
                  "Hit threshold as a fraction of the largest force")
      ->capture_default_str();
  cmd->add_flag("--keep-bad-hits", a->request.estimation.keep_bad_hits,
                "Use double and clipped hits (only flag them)");
  cmd->add_option("--fs-hz", a->request.estimation.fs_hz,
                  "Sample rate (Hz) when recordings have no t_s column")
      ->check(PositiveNumber());
  cmd->add_option("--prior-spread", a->request.prior_relative_sd,
                  "Relative spread of the nominal model as the one-test fit's prior, used when the "
                  "tests show fewer modes than masses")
      ->check(PositiveNumber())
      ->capture_default_str();
  cmd->add_option("--sensors", a->request.sensors,
                  "Sensors file whose sensitivities state their certificate's uncertainty: the "
                  "intervals of m, k and c carry its calibration part beside the statistical one");
  AddModeOptions(cmd, a->request.modes);
  cmd->add_option("-o,--output", a->output, "Updated model file (JSON, chain form)")->required();
  cmd->add_flag("--accept-flagged", a->accept_flagged,
                "Write -o even when the result is flagged (exit 6 without it, nothing written); "
                "the file carries the verdict");
  cmd->add_option("--report", a->report,
                  "Directory for the report: validation.txt, report.json (all results), "
                  "frf_overlay.csv (test vs models)");
}

}  // namespace vibid::cli
