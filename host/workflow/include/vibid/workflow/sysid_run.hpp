// System identification from a recording as the `vibid` commands run it (arx, pem, tfest,
// compare): the record read (columns, detrend, decimation, sample ranges), the estimation, and the
// report (JSON and text) with fits, residual tests, validation and the continuous form. The CLI,
// the Python package and the bench call these.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "vibid/numerics/least_squares.hpp"
#include "vibid/sysid/fit.hpp"
#include "vibid/sysid/io_data.hpp"
#include "vibid/sysid/poly_model.hpp"

namespace vibid::workflow {

/// REC.csv, its input and output columns (NAME[:UNIT|*FACTOR]), --fs-hz, --detrend (none, mean,
/// linear) and --decimate (1..1000).
struct SysidRecord {
  std::string path;
  std::string input;
  std::string output;
  std::optional<double> fs_hz;
  std::string detrend = "none";
  int decimate = 1;
};

/// The whole record (detrended, decimated) as checked IoData.
sysid::IoData LoadIoData(const SysidRecord& args);

/// Part `range` ("a:b", empty for all) of `data`; `option` names it in errors.
sysid::IoData ApplyRange(const sysid::IoData& data, const std::string& range,
                         const std::string& option);

nlohmann::json ResidualJson(const sysid::ResidualTests& t);
/// Residual tests when the record allows them (more than 4 x 25 samples, nonzero residuals).
std::optional<sysid::ResidualTests> TryResidualTests(const Eigen::VectorXd& residual,
                                                     const Eigen::VectorXd& input);

/// A polynomial model in the file format arx and pem write: A, B, C, D, F in powers of q^-1 (B
/// with its nk leading zeros), nk, dt_s.
nlohmann::json PolyModelJson(const sysid::PolyModel& m);
sysid::PolyModel PolyModelFromJson(const nlohmann::json& j, const std::string& source);

/// JSON array of a vector, and a vector from a JSON array of finite numbers (InputError naming
/// `source` and `key` otherwise).
std::vector<double> ToStdVector(const Eigen::VectorXd& v);
Eigen::VectorXd JsonVector(const nlohmann::json& j, const std::string& key,
                           const std::string& source);

/// Number formatting for the text reports.
std::string FormatNumber(double v);
std::string FormatVector(const Eigen::VectorXd& v);

/// "na=2,nb=2,nk=1" or MATLAB's order vectors: arx [na nb nk], armax [na nb nc nk], oe [nb nf
/// nk], bj [nb nc nd nf nk] written "2,2,1".
sysid::PolyOrders ParseOrders(const std::string& text, sysid::Structure s);

/// NumericalError naming `what` when the solver failed numerically.
void CheckSolver(const numerics::SolverSummary& s, const std::string& what);

/// What a command prints: the JSON (--json, and the model file) and the text.
struct SysidReport {
  nlohmann::json json;
  std::string text;
  /// What the text's CAUTION lines say (also json["cautions"]): residual tests that fail. Empty
  /// for a model whose own tests pass.
  std::vector<std::string> cautions;
};

/// The CAUTION lines for residual tests that fail: not white (Ljung-Box), not independent of the
/// input; each names the statistic, its threshold and what it means for the fit and the stds.
std::vector<std::string> ResidualCautions(const sysid::ResidualTests& tests);

/// `vibid greybox cart`: the cart-track model's physical parameters (sysid/greybox.hpp).
struct GreyboxRequest {
  SysidRecord record;
  int carts = 1;
  std::string input_kind = "force";  ///< force, position.
  std::string fix;                   ///< NAME=VALUE,... held fixed.
  std::string ic = "zero";
  std::string estimate_range;
};

SysidReport RunGreybox(const GreyboxRequest& request);

struct PolyRequest {
  SysidRecord record;
  std::string estimate_range;  ///< Samples FIRST:LAST used for estimation; empty: all.
  std::string validate_range;  ///< Samples FIRST:LAST for a validation fit; empty: none.
  bool d2c = false;            ///< Also the continuous-time equivalent (ZOH inverse).
};

struct ArxRequest {
  PolyRequest poly;
  int na = -1;
  int nb = -1;
  int nk = 1;
  std::string select;  ///< aic or fpe: na = nb chosen over 1..max_order; empty: na, nb given.
  int max_order = 10;
};

struct PemRequest {
  PolyRequest poly;
  std::string structure;  ///< arx, armax, oe, bj.
  std::string orders;     ///< ParseOrders' text.
  int max_iterations = 200;
};

struct TfestRequest {
  SysidRecord record;
  int np = 2;
  int nz = 0;
  std::string ic = "zero";  ///< zero, estimate.
  std::string estimate_range;
  std::string validate_range;
  int max_iterations = 200;
};

struct CompareRequest {
  SysidRecord record;
  std::string model;  ///< Model file: polynomial (arx, pem), num/den (tfest), or a rig model.
  std::string horizon = "inf";   ///< inf (simulation) or a prediction horizon in samples.
  std::string method = "exact";  ///< exact, euler, rk4 (continuous-time models).
  int substeps = 1;
  std::string ic = "zero";
  std::string range;
  int input_dof = 1;   ///< Rig models: the receptance from this DOF (from 1) ...
  int output_dof = 1;  ///< ... to this one.
};

struct CompareReport : SysidReport {
  Eigen::VectorXd t_s;
  Eigen::VectorXd y;        ///< The record's output.
  Eigen::VectorXd y_model;  ///< The model's simulated (or predicted) output.
};

SysidReport RunArx(const ArxRequest& request);
SysidReport RunPem(const PemRequest& request);
SysidReport RunTfest(const TfestRequest& request);
CompareReport RunCompare(const CompareRequest& request);

}  // namespace vibid::workflow
