// Shared pieces of the system-identification commands: the record options every command takes,
// JSON forms of solver summaries and residual tests, model files.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "vibid/sysid/fit.hpp"
#include "vibid/sysid/io_data.hpp"
#include "vibid/numerics/least_squares.hpp"
#include "vibid/sysid/poly_model.hpp"
#include "vibid/workflow/sysid_run.hpp"

namespace vibid::cli {

/// REC.csv, --input, --output, --fs-hz, --detrend, --decimate and a sample range.
using RecordArgs = workflow::SysidRecord;

void AddRecordOptions(CLI::App& cmd, RecordArgs& args);

// The record, reports and model files of the workflow library, by their CLI names.
using workflow::ApplyRange;
using workflow::CheckSolver;
using workflow::FormatNumber;
using workflow::FormatVector;
using workflow::JsonVector;
using workflow::LoadIoData;
using workflow::PolyModelFromJson;
using workflow::PolyModelJson;
using workflow::ResidualJson;
using workflow::ToStdVector;
using workflow::TryResidualTests;

/// Writes `j` to `out_path` (when given, atomically), then prints `j` when `json`, else `text`.
void Emit(const nlohmann::json& j, const std::string& text, bool json, const std::string& out_path);

void RegisterArxCommand(CLI::App& app);
void RegisterPemCommand(CLI::App& app);
void RegisterTfestCommand(CLI::App& app);
void RegisterCompareCommand(CLI::App& app);
void RegisterGreyboxCommand(CLI::App& app);

}  // namespace vibid::cli
