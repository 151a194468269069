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

namespace vibid::cli {

/// REC.csv, --input, --output, --fs-hz, --detrend, --decimate and a sample range.
struct RecordArgs {
  std::string path;
  std::string input;
  std::string output;
  std::optional<double> fs_hz;
  std::string detrend = "none";
  int decimate = 1;
};

void AddRecordOptions(CLI::App& cmd, RecordArgs& args);

/// The whole record (detrended, decimated) as checked IoData.
sysid::IoData LoadIoData(const RecordArgs& args);

/// Part `range` ("a:b", empty for all) of `data`; `option` names it in errors.
sysid::IoData ApplyRange(const sysid::IoData& data, const std::string& range,
                         const std::string& option);

nlohmann::json ResidualJson(const sysid::ResidualTests& t);
/// Residual tests when the record allows them (more than 4 × 25 samples, nonzero residuals).
std::optional<sysid::ResidualTests> TryResidualTests(const Eigen::VectorXd& residual,
                                                     const Eigen::VectorXd& input);

/// A polynomial model in the file format arx and pem write: A, B, C, D, F in powers of q⁻¹ (B with
/// its nk leading zeros), nk, dt_s.
nlohmann::json PolyModelJson(const sysid::PolyModel& m);
sysid::PolyModel PolyModelFromJson(const nlohmann::json& j, const std::string& source);

/// JSON array of a vector, and a vector from a JSON array of finite numbers (InputError naming
/// `source` and `key` otherwise).
std::vector<double> ToStdVector(const Eigen::VectorXd& v);
Eigen::VectorXd JsonVector(const nlohmann::json& j, const std::string& key,
                           const std::string& source);

/// Number formatting for the text (non-JSON) output.
std::string FormatNumber(double v);
std::string FormatVector(const Eigen::VectorXd& v);

/// Writes `j` to `out_path` (when given, atomically), then prints `j` when `json`, else `text`.
void Emit(const nlohmann::json& j, const std::string& text, bool json, const std::string& out_path);

void RegisterArxCommand(CLI::App& app);
void RegisterPemCommand(CLI::App& app);
void RegisterTfestCommand(CLI::App& app);
void RegisterCompareCommand(CLI::App& app);
void RegisterGreyboxCommand(CLI::App& app);

}  // namespace vibid::cli
