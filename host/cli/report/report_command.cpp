// `vibid report`: one HTML page with inline SVG from the files the other commands write — the
// identification (`vibid identify --report DIR`) and observer recordings (`vibid dob run`).
#include <iostream>
#include <string>

#include "cli_support.hpp"
#include "common/command.hpp"
#include "commands.hpp"
#include "vibid/workflow/report_page.hpp"
#include "vibid/common/atomic_file.hpp"

namespace vibid::cli {
namespace {

constexpr const char* kReportHelp =
    "One HTML page (inline SVG, no scripts) from an identification (`vibid identify --report "
    "DIR`): validation\n"
    "table and FRFs measured/nominal/updated; and from an observer recording (`vibid dob run`): "
    "fit of each\n"
    "estimate to the measured force and the traces over time.";

struct ReportArgs {
  workflow::ReportRequest request;
  std::string out;
};

void Run(const ReportArgs& a) {
  WriteFileAtomic(a.out, workflow::ReportPage(a.request));
  std::cout << "wrote " << a.out << "\n";
}

}  // namespace

void RegisterReportCommands(CLI::App& app) {
  const auto [cmd, a] = AddCommand<ReportArgs>(app, "report", kReportHelp, Run);
  cmd->add_option("--identify", a->request.identify_dir,
                  "Directory written by `vibid identify --report`");
  cmd->add_option("--truth", a->request.truth,
                  "Model file of the rig's true values (e.g. `vibid-emu --print-truth`): adds the "
                  "error of the update");
  cmd->add_option("--dob", a->request.dob_recording,
                  "Recording with the measured force and the estimates (CSV)");
  cmd->add_option("--measured", a->request.measured, "Measured force column of --dob");
  cmd->add_option("--estimate", a->request.estimates,
                  "COLUMN[=LABEL]: an estimate to score and plot; repeat for several");
  cmd->add_option("--skip-s", a->request.skip_s,
                  "Seconds left out at each end of --dob (start-up, filter edges)")
      ->check(NonNegativeNumber())
      ->capture_default_str();
  cmd->add_option("--note", a->request.notes,
                  "A line for the top of the report (rig, firmware, checks); repeat for several");
  cmd->add_option("--title", a->request.title, "Page title")->capture_default_str();
  cmd->add_flag("--accept-flagged", a->request.accept_flagged,
                "Report an identification whose verdict is flagged (refused otherwise; the page "
                "shows the verdict in red at the top)");
  cmd->add_option("-o,--output", a->out, "HTML file to write")->required();
}

}  // namespace vibid::cli
