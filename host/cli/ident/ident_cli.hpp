// The identification commands' options and what they say on the terminal. The decisions (impact or
// Welch, defaults, hit verdicts, the JSON of results) are the workflow library's; this file adds
// the options that fill its requests and the printing.
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "vibid/workflow/estimate.hpp"
#include "vibid/workflow/result_json.hpp"

namespace vibid::cli {

using EstimationArgs = workflow::EstimationOptions;
using workflow::DescribeHits;
using workflow::DiagramToJson;
using workflow::Estimated;
using workflow::EstimateFromRecording;
using workflow::JoinColumns;
using workflow::ModesFromJson;
using workflow::ModesTable;
using workflow::ModesToJson;

/// Adds --force/--response (required when `require_columns`) and every estimation option.
void AddEstimationOptions(CLI::App* cmd, EstimationArgs& args, bool require_columns,
                          const std::string& kind_default);

/// An FRF file as it is, or a recording estimated first (workflow::LoadOrEstimate); what the
/// estimation said goes to stderr and into `notes`.
ident::Frf LoadOrEstimate(const std::string& path, const EstimationArgs& args,
                          std::vector<std::string>& notes);

/// Says on stderr what the estimation of `path` warned of (and its processing note when
/// `say_note`), and keeps the note, the warnings and one line per hit in `notes` for the report.
void KeepEstimationNotes(const std::string& path, const Estimated& e, bool say_note,
                         std::vector<std::string>& notes);

}  // namespace vibid::cli
