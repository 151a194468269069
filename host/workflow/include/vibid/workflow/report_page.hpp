// The HTML report `vibid report` writes: one page with inline SVG from the identification
// (`vibid identify --report DIR`: validation tables, FRFs measured/nominal/updated, the
// stabilization diagram) and from an observer recording (`vibid dob run`: each estimate's
// agreement with the measured force, the traces over time).
#pragma once

#include <string>
#include <vector>

namespace vibid::workflow {

struct ReportRequest {
  std::string title = "vibid rig report";
  std::string identify_dir;            ///< Written by `vibid identify --report`; empty: none.
  std::string truth;                   ///< Model file of the rig's true values; empty: none.
  std::string dob_recording;           ///< Recording with the measured force and the estimates.
  std::string measured;                ///< Its measured force column.
  std::vector<std::string> estimates;  ///< COLUMN[=LABEL] of each estimate.
  double skip_s = 0.0;                 ///< Left out at each end of the recording.
  std::vector<std::string> notes;      ///< Lines for the top of the page.
  /// Report a flagged identification (its verdict in red at the top); otherwise refused
  /// (FlaggedError naming --accept-flagged).
  bool accept_flagged = false;
};

/// The page, the identification's verdict first. InputError naming the option or file when the
/// request is incomplete or a file does not read.
std::string ReportPage(const ReportRequest& request);

}  // namespace vibid::workflow
