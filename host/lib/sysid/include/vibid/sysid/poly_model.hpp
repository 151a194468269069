// Discrete-time polynomial models of the prediction-error family and the ARX estimator.
//
//   A(q) y(t) = B(q)/F(q) u(t) + C(q)/D(q) e(t)
//
// with A, C, D, F monic in q⁻¹ and B(q) = b0 q^-nk + b1 q^-(nk+1) + ... + b_{nb-1} q^-(nk+nb-1).
// ARX: C = D = F = 1. ARMAX: D = F = 1. OE: A = C = D = 1. Box–Jenkins: A = 1. The conventions are
// MATLAB's (arx, armax, oe, bj): nb counts B coefficients, nk the delay in samples.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "vibid/sysid/io_data.hpp"

namespace vibid::sysid {

enum class Structure { kArx, kArmax, kOe, kBj };

/// "arx", "armax", "oe", "bj"; ParseStructure throws InputError on anything else.
const char* StructureName(Structure s);
Structure ParseStructure(const std::string& name);

struct PolyOrders {
  int na = 0;  ///< A order (ARX, ARMAX).
  int nb = 1;  ///< Number of B coefficients.
  int nc = 0;  ///< C order (ARMAX, BJ).
  int nd = 0;  ///< D order (BJ).
  int nf = 0;  ///< F order (OE, BJ).
  int nk = 1;  ///< Input delay, samples.

  int Parameters() const { return na + nb + nc + nd + nf; }
};

/// Checks the orders against the structure (e.g. OE has na = nc = nd = 0) and the record length;
/// InputError naming the problem.
void ValidateOrders(Structure s, const PolyOrders& o, Eigen::Index samples);

struct PolyModel {
  Structure structure = Structure::kArx;
  PolyOrders orders;
  double dt_s = 1.0;
  // Full polynomials in ascending powers of q⁻¹ (B includes its nk leading zeros).
  Eigen::VectorXd a{Eigen::VectorXd::Ones(1)};
  Eigen::VectorXd b{Eigen::VectorXd::Zero(1)};
  Eigen::VectorXd c{Eigen::VectorXd::Ones(1)};
  Eigen::VectorXd d{Eigen::VectorXd::Ones(1)};
  Eigen::VectorXd f{Eigen::VectorXd::Ones(1)};
  /// Covariance of the free parameters, ordered [a1..ana, b0..b_{nb-1}, c1.., d1.., f1..].
  Eigen::MatrixXd covariance;
  double noise_variance = 0.0;  ///< Variance of the one-step prediction errors e(t).

  /// Free parameters in the covariance's order.
  Eigen::VectorXd Parameters() const;
  /// Builds the polynomials from a parameter vector in that order.
  void SetParameters(Eigen::Ref<const Eigen::VectorXd> theta);
};

/// Simulated (noise-free) output B/(A F) u, zero initial conditions.
Eigen::VectorXd SimulatePoly(const PolyModel& m, Eigen::Ref<const Eigen::VectorXd> u);

/// One-step prediction errors e(t) = D/C (A y − B/F u), zero initial conditions.
Eigen::VectorXd PredictionErrors(const PolyModel& m, const IoData& data);

/// k-step-ahead prediction ŷ(t|t−k) (k ≥ 1), zero initial conditions (Ljung, System
/// Identification, 2nd ed., eq. 3.31):  ŷ = H̄_k (D/C)(B/F) u + (1 − H̄_k A D/C) y,  where H̄_k is
/// the first k impulse-response coefficients of the noise model H = C/(A D). k = 1 is the one-step
/// predictor; for OE models (H = 1) every horizon equals simulation.
Eigen::VectorXd PredictKStep(const PolyModel& m, const IoData& data, int k);

struct ArxResult {
  PolyModel model;
  double loss = 0.0;           ///< Mean squared equation error on the rows used.
  Eigen::Index rows_used = 0;  ///< Regression rows (samples with a full regressor).
};

/// ARX by linear least squares on the QR factor of the regressor matrix (never normal equations).
/// Rows t = max(na, nk + nb − 1) … N − 1 (0-based), i.e. no regressor reaches before the record.
/// InputError when the orders leave fewer rows than parameters, when the input is not persistently
/// exciting for nb coefficients, or the regressors are otherwise collinear.
ArxResult EstimateArx(const IoData& data, const PolyOrders& orders);

/// Akaike's criteria for a model with p parameters and loss V on N samples:
///   AIC = N log V + 2p,   FPE = V (1 + p/N)/(1 − p/N).
double Aic(double loss, int parameters, Eigen::Index samples);
double Fpe(double loss, int parameters, Eigen::Index samples);

enum class OrderCriterion { kAic, kFpe };

struct OrderCandidate {
  PolyOrders orders;
  double loss = 0.0;
  double criterion = 0.0;
};

/// ARX orders na = nb = n for n in [n_min, n_max] (nk fixed), picks the smallest criterion.
struct OrderSelection {
  std::vector<OrderCandidate> candidates;
  std::size_t best = 0;
};
OrderSelection SelectArxOrder(const IoData& data, int n_min, int n_max, int nk,
                              OrderCriterion criterion);

}  // namespace vibid::sysid
