#include "vibid/sysid/tfest.hpp"

#include "vibid/sysid/correlated_covariance.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "search.hpp"
#include "vibid/common/error.hpp"
#include "vibid/numerics/polynomial.hpp"
#include "vibid/sysid/fit.hpp"
#include "vibid/sysid/instrumental.hpp"

namespace vibid::sysid {

const char* InitialConditionName(InitialCondition ic) {
  return ic == InitialCondition::kZero ? "zero" : "estimate";
}

InitialCondition ParseInitialCondition(const std::string& name) {
  if (name == "zero") return InitialCondition::kZero;
  if (name == "estimate") return InitialCondition::kEstimate;
  throw InputError("unknown initial-condition handling '" + name + "' (known: zero, estimate)");
}

void TfestOptions::Validate() const {
  Require(np >= 1, "tfest: np (number of poles) must be at least 1");
  Require(nz >= 0 && nz < np, "tfest: nz (number of zeros) must satisfy 0 <= nz < np");
  Require(np <= 20, "tfest: np above 20 is beyond what a continuous-time fit can resolve");
  Require(srivc_iterations >= 1, "tfest: srivc_iterations must be at least 1");
  Require(std::isfinite(srivc_tolerance) && srivc_tolerance > 0.0,
          "tfest: srivc_tolerance must be > 0");
  solver.Validate();
}

namespace {

Eigen::MatrixXd Companion(const Eigen::VectorXd& monic_den) {
  const Eigen::Index n = monic_den.size() - 1;
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  a.row(0) = -monic_den.tail(n).transpose();
  for (Eigen::Index i = 1; i < n; ++i) a(i, i - 1) = 1.0;
  return a;
}

Eigen::VectorXd UnitVector(Eigen::Index n) {
  Eigen::VectorXd e = Eigen::VectorXd::Zero(n);
  e[0] = 1.0;
  return e;
}

/// Columns j = 0..n−1 hold the derivative of order j of the filtered signal (state column n−1−j).
Eigen::MatrixXd Derivatives(const Eigen::MatrixXd& states) { return states.rowwise().reverse(); }

/// Forced response through 1/den (or free response from x0 = e1 when `free`), as derivatives.
Eigen::MatrixXd FilteredDerivatives(const Eigen::VectorXd& monic_den, const Eigen::VectorXd& signal,
                                    double dt_s, Hold hold, bool free) {
  const Eigen::Index n = monic_den.size() - 1;
  const Eigen::VectorXd x0 = free ? UnitVector(n) : Eigen::VectorXd::Zero(n);
  const Eigen::VectorXd input = free ? Eigen::VectorXd::Zero(signal.size()) : signal;
  return Derivatives(SimulateStates(Companion(monic_den), UnitVector(n), input, dt_s, hold, x0));
}

/// FilteredDerivatives of a forced response into `out` (storage reused when the size matches).
void FilteredDerivativesInto(const Eigen::VectorXd& monic_den, const Eigen::VectorXd& signal,
                             double dt_s, Hold hold, Eigen::MatrixXd& out) {
  const Eigen::Index n = monic_den.size() - 1;
  SimulateStatesInto(Companion(monic_den), UnitVector(n), signal, dt_s, hold,
                     Eigen::VectorXd::Zero(n), true, out);
}

/// out = sign Σ_i c_i D.col(i + shift), written in place (sign ±1: the same bits as negating
/// after).
void CombineInto(const Eigen::VectorXd& descending, const Eigen::MatrixXd& derivs,
                 Eigen::Index shift, double sign, Eigen::Ref<Eigen::VectorXd> out) {
  const Eigen::Index m = descending.size() - 1;
  out.setZero();
  for (Eigen::Index i = 0; i <= m; ++i) out += (sign * descending[m - i]) * derivs.col(i + shift);
}

/// Σ_i c_i D.col(i + shift) for a polynomial c in descending powers (c_i multiplies s^i).
Eigen::VectorXd Combine(const Eigen::VectorXd& descending, const Eigen::MatrixXd& derivs,
                        Eigen::Index shift) {
  const Eigen::Index m = descending.size() - 1;
  Eigen::VectorXd out = Eigen::VectorXd::Zero(derivs.rows());
  for (Eigen::Index i = 0; i <= m; ++i) out += descending[m - i] * derivs.col(i + shift);
  return out;
}

bool StableContinuous(const Eigen::VectorXd& den) {
  for (const numerics::Complex& r : numerics::PolynomialRoots(den)) {
    if (!(r.real() < 0.0)) return false;
  }
  return true;
}

/// Model output and its Jacobian in [a_{n-1}..a_0, b_m..b_0, p_{n-1}..p_0] (p only when given).
bool OutputAndJacobian(const Eigen::VectorXd& den, const Eigen::VectorXd& num,
                       const Eigen::VectorXd* ic, const IoData& data, Eigen::VectorXd& y_hat,
                       Eigen::MatrixXd* jac) {
  if (!StableContinuous(den)) return false;
  const Eigen::Index n = den.size() - 1;
  const Eigen::Index m = num.size() - 1;
  const Eigen::MatrixXd z = FilteredDerivatives(den, data.u, data.dt_s, Hold::kZero, false);
  y_hat = Combine(num, z, 0);
  Eigen::MatrixXd g;
  if (ic != nullptr) {
    g = FilteredDerivatives(den, data.u, data.dt_s, Hold::kZero, true);
    y_hat += Combine(*ic, g, 0);
  }
  if (jac == nullptr) return y_hat.allFinite();
  const Eigen::Index cols = n + m + 1 + (ic != nullptr ? n : 0);
  jac->resize(data.samples(), cols);
  const Eigen::VectorXd den2 = numerics::MultiplyPolynomials(den, den);
  const Eigen::MatrixXd w = FilteredDerivatives(den2, data.u, data.dt_s, Hold::kZero, false);
  Eigen::MatrixXd h;
  if (ic != nullptr) h = FilteredDerivatives(den2, data.u, data.dt_s, Hold::kZero, true);
  for (Eigen::Index j = 0; j < n; ++j) {
    const Eigen::Index k = n - 1 - j;  // coefficient of s^k
    Eigen::VectorXd col = -Combine(num, w, k);
    if (ic != nullptr) col -= Combine(*ic, h, k);
    jac->col(j) = col;
  }
  for (Eigen::Index j = 0; j <= m; ++j) jac->col(n + j) = z.col(m - j);
  if (ic != nullptr) {
    for (Eigen::Index j = 0; j < n; ++j) jac->col(n + m + 1 + j) = g.col(n - 1 - j);
  }
  return y_hat.allFinite() && jac->allFinite();
}

Eigen::VectorXd MonicFromTail(const Eigen::VectorXd& tail) {
  Eigen::VectorXd p(tail.size() + 1);
  p[0] = 1.0;
  p.tail(tail.size()) = tail;
  return p;
}

struct SrivcOutcome {
  TransferFunction tf;     ///< den: the prefilter before the first pass; num: empty before it.
  int iterations = -1;     ///< Last pass done (0: the state-variable-filter least squares).
  bool ok = false;         ///< At least one pass gave an estimate.
  bool converged = false;  ///< The relative parameter change fell below the tolerance.
  Eigen::VectorXd
      previous;  ///< Parameters after the pass before the last, for the convergence test.
};

/// Starting prefilter 1/(s + λ)^np.
SrivcOutcome SvfStart(int np, double lambda_rad_s) {
  SrivcOutcome out;
  out.tf.den = Eigen::VectorXd::Ones(1);
  for (int i = 0; i < np; ++i)
    out.tf.den = numerics::MultiplyPolynomials(out.tf.den, Eigen::Vector2d(1.0, lambda_rad_s));
  return out;
}

/// Record-length buffers of the SRIVC passes, allocated by the first pass and reused by every later
/// one (fresh megabyte-sized buffers per pass cost more in page faults than the filtering itself).
struct SrivcWork {
  Eigen::MatrixXd yf, uf, w, phi, zeta;
  Eigen::VectorXd target;
};

/// Passes up to `last_pass` on top of `state`: the first (num still empty) is the
/// state-variable-filter least squares with the prefilter 1/den, every later one an SRIVC pass with
/// the current model.
void SrivcPasses(const IoData& data, int np, int nz, int last_pass, const TfestOptions& options,
                 SrivcWork& work, SrivcOutcome& state) {
  const Eigen::Index n = np;
  const Eigen::Index m = nz;
  const Eigen::Index p = n + m + 1;
  Eigen::VectorXd den = state.tf.den;
  Eigen::VectorXd num = state.tf.num;
  for (int iter = state.iterations + 1; iter <= last_pass && !state.converged; ++iter) {
    // The measured output is not stepped: first-order hold follows it more closely.
    FilteredDerivativesInto(den, data.y, data.dt_s, Hold::kFirst, work.yf);
    FilteredDerivativesInto(den, data.u, data.dt_s, Hold::kZero, work.uf);
    const Eigen::MatrixXd& yf = work.yf;
    const Eigen::MatrixXd& uf = work.uf;
    Eigen::VectorXd& target = work.target;
    target = data.y;
    for (Eigen::Index k = 0; k < n; ++k) target -= den[n - k] * yf.col(k);
    Eigen::MatrixXd& phi = work.phi;
    phi.resize(data.samples(), p);
    for (Eigen::Index j = 0; j < n; ++j) phi.col(j) = -yf.col(n - 1 - j);
    for (Eigen::Index j = 0; j <= m; ++j) phi.col(n + j) = uf.col(m - j);
    Eigen::MatrixXd& zeta = work.zeta;
    zeta = phi;
    if (num.size() > 0) {
      // Instruments: the prefiltered noise-free output of the current model, exact for the ZOH
      // input.
      FilteredDerivativesInto(numerics::MultiplyPolynomials(den, den), data.u, data.dt_s,
                              Hold::kZero, work.w);
      for (Eigen::Index j = 0; j < n; ++j) CombineInto(num, work.w, n - 1 - j, -1.0, zeta.col(j));
    }
    Eigen::VectorXd theta;
    if (!SolveInstrumental(zeta, phi, target, theta)) break;
    den = numerics::StabilizeContinuous(MonicFromTail(theta.head(n)));
    num = theta.tail(m + 1);
    state.tf = TransferFunction{num, den};
    state.iterations = iter;
    state.ok = true;
    Eigen::VectorXd current(p);
    current << den.tail(n), num;
    if (state.previous.size() == p &&
        (current - state.previous).norm() <= options.srivc_tolerance * current.norm()) {
      state.converged = true;
    }
    state.previous = current;
  }
}

}  // namespace

Eigen::VectorXd SimulateWithIc(const TransferFunction& tf, Eigen::Ref<const Eigen::VectorXd> ic_num,
                               Eigen::Ref<const Eigen::VectorXd> u, double dt_s) {
  const TransferFunction t = Normalized(tf);
  Eigen::VectorXd y = Simulate(t, u, dt_s);
  if (ic_num.size() > 0 && ic_num.cwiseAbs().maxCoeff() > 0.0) {
    Require(ic_num.size() <= t.Order(),
            "initial-condition polynomial must have fewer coefficients than den");
    const Eigen::MatrixXd g = FilteredDerivatives(t.den, u, dt_s, Hold::kZero, true);
    y += Combine(ic_num, g, 0);
  }
  return y;
}

Eigen::VectorXd FitInitialCondition(const TransferFunction& tf, const IoData& data) {
  const TransferFunction t = Normalized(tf);
  const Eigen::Index n = t.Order();
  const Eigen::MatrixXd g = FilteredDerivatives(t.den, data.u, data.dt_s, Hold::kZero, true);
  const Eigen::VectorXd rest = data.y - Simulate(t, data.u, data.dt_s);
  // g column k is the free response of s^k/A; P's descending coefficients are reversed.
  const Eigen::VectorXd ascending = g.colPivHouseholderQr().solve(rest);
  return ascending.reverse().eval().head(n);
}

CtOeResult FitContinuousOe(const IoData& data, const CtParameterization& param,
                           Eigen::Ref<const Eigen::VectorXd> theta0, InitialCondition ic,
                           const numerics::SolverOptions& options) {
  options.Validate();
  const Eigen::Index n = param.np;
  const Eigen::Index m = param.nz;
  const Eigen::Index q = theta0.size();
  const bool with_ic = ic == InitialCondition::kEstimate;
  Eigen::VectorXd theta(q + (with_ic ? n : 0));
  theta.head(q) = theta0;
  if (with_ic) theta.tail(n).setZero();
  const numerics::ResidualFunction fn = [&](const Eigen::VectorXd& th, Eigen::VectorXd& r,
                                            Eigen::MatrixXd* j) {
    Eigen::VectorXd coef;
    Eigen::MatrixXd dcoef;
    if (!param.map(th.head(q), coef, j != nullptr ? &dcoef : nullptr)) return false;
    const Eigen::VectorXd den = MonicFromTail(coef.head(n));
    const Eigen::VectorXd num = coef.tail(m + 1);
    const Eigen::VectorXd p = with_ic ? Eigen::VectorXd(th.tail(n)) : Eigen::VectorXd();
    Eigen::VectorXd y_hat;
    Eigen::MatrixXd jc;
    if (!OutputAndJacobian(den, num, with_ic ? &p : nullptr, data, y_hat,
                           j != nullptr ? &jc : nullptr)) {
      return false;
    }
    r = data.y - y_hat;
    if (j != nullptr) {
      j->resize(data.samples(), th.size());
      j->leftCols(q) = -jc.leftCols(n + m + 1) * dcoef;
      if (with_ic) j->rightCols(n) = -jc.rightCols(n);
    }
    return true;
  };
  CtOeResult res;
  numerics::Solution solution;
  res.summary = MinimizePredictionError(fn, theta, options, solution);
  res.theta = theta.head(q);
  res.ic_num = with_ic ? Eigen::VectorXd(theta.tail(n)) : Eigen::VectorXd::Zero(n);
  if (solution.residuals.size() == data.samples()) {
    res.residual = std::move(solution.residuals);
    res.covariance = numerics::CovarianceFromFactor(solution.r_factor, res.residual);
    if (solution.jacobian.rows() == data.samples()) {
      const CorrelatedCovariance c =
          CovarianceForCorrelatedResiduals(solution.jacobian, res.residual);
      res.covariance_correlated = c.covariance;
      res.correlation_lags = c.lags;
    }
  } else {
    fn(theta, res.residual, nullptr);
  }
  return res;
}

namespace {

// The start SRIVC is iterated from, with its simulation fit (percent) and filter frequency.
struct ScreenedStart {
  SrivcOutcome outcome;
  double fit = -std::numeric_limits<double>::infinity();
  double lambda_rad_s = 0.0;
};

// Starting filters across the band: λ from 1 % to 30 % of the Nyquist frequency. SRIVC converges
// to the same fixed point from any start in its basin, so the starts are screened after the
// state-variable-filter pass, and only the best by simulation fit is iterated on (rather than
// every start to convergence, which cost four times the passes).
ScreenedStart ScreenStarts(const IoData& data, const TfestOptions& options, SrivcWork& work) {
  constexpr int kScreeningPasses = 0;
  const double nyquist_rad_s = std::acos(-1.0) / data.dt_s;
  ScreenedStart best;
  for (const double fraction : {0.01, 0.03, 0.1, 0.3}) {
    SrivcOutcome o = SvfStart(options.np, fraction * nyquist_rad_s);
    SrivcPasses(data, options.np, options.nz, std::min(kScreeningPasses, options.srivc_iterations),
                options, work, o);
    if (!o.ok) continue;
    const double fit = FitPercent(data.y, Simulate(o.tf, data.u, data.dt_s));
    if (std::isfinite(fit) && fit > best.fit) {
      best.fit = fit;
      best.outcome = o;
      best.lambda_rad_s = fraction * nyquist_rad_s;
    }
  }
  return best;
}

// The coefficients themselves as the parameters: [den tail, num].
CtParameterization DirectParameterization(int np, int nz) {
  CtParameterization identity;
  identity.np = np;
  identity.nz = nz;
  identity.map = [](const Eigen::VectorXd& th, Eigen::VectorXd& coef, Eigen::MatrixXd* j) {
    coef = th;
    if (j != nullptr) *j = Eigen::MatrixXd::Identity(th.size(), th.size());
    return true;
  };
  return identity;
}

void StoreOeRefinement(const CtOeResult& oe, const IoData& data, int np, int nz, Eigen::Index p,
                       TfestResult& res) {
  res.summary = oe.summary;
  res.tf = TransferFunction{oe.theta.tail(nz + 1), MonicFromTail(oe.theta.head(np))};
  res.ic_num = oe.ic_num;
  res.covariance = oe.covariance;
  res.den_std = Eigen::VectorXd::Zero(np + 1);
  res.num_std = Eigen::VectorXd::Zero(nz + 1);
  if (res.covariance.rows() == p) {
    const Eigen::VectorXd sd = res.covariance.diagonal().cwiseSqrt();
    res.den_std.tail(np) = sd.head(np);
    res.num_std = sd.segment(np, nz + 1);
  }
  res.noise_variance = oe.residual.squaredNorm() /
                       static_cast<double>(std::max<Eigen::Index>(data.samples() - p, 1));
  res.fit_percent = FitPercent(data.y, data.y - oe.residual);
}

}  // namespace

TfestResult EstimateTf(const IoData& data, const TfestOptions& options) {
  options.Validate();
  const int np = options.np;
  const int nz = options.nz;
  const Eigen::Index p = np + nz + 1 + (options.ic == InitialCondition::kEstimate ? np : 0);
  Require(data.samples() >= 10 * p,
          "orders too high for the data: tfest with np=" + std::to_string(np) +
              ", nz=" + std::to_string(nz) + " needs at least " + std::to_string(10 * p) +
              " samples, the record has " + std::to_string(data.samples()));
  TfestResult res;
  SrivcWork work;
  ScreenedStart start = ScreenStarts(data, options, work);
  SrivcOutcome& best = start.outcome;
  if (!best.ok) {
    res.summary.termination = numerics::TerminationType::kNumericalFailure;
    res.summary.message =
        "no starting model: the filtered regressors are rank deficient (input not exciting enough)";
    return res;
  }
  if (best.iterations < options.srivc_iterations && !best.converged) {
    SrivcPasses(data, np, nz, options.srivc_iterations, options, work, best);
    const double fit = FitPercent(data.y, Simulate(best.tf, data.u, data.dt_s));
    if (std::isfinite(fit)) start.fit = fit;
  }
  char init[96];
  std::snprintf(init, sizeof init, "svf(lambda=%.4g rad/s)+srivc(%d iterations)",
                start.lambda_rad_s, best.iterations);
  res.initialization = init;

  Eigen::VectorXd theta0(np + nz + 1);
  theta0 << best.tf.den.tail(np), best.tf.num;
  if (!options.refine) {
    res.tf = best.tf;
    res.ic_num = Eigen::VectorXd::Zero(np);
    res.den_std = Eigen::VectorXd::Zero(np + 1);
    res.num_std = Eigen::VectorXd::Zero(nz + 1);
    res.fit_percent = start.fit;
    res.summary.termination = numerics::TerminationType::kParameterTolerance;
    res.summary.message = "SRIVC estimate without output-error refinement";
    return res;
  }
  const CtOeResult oe =
      FitContinuousOe(data, DirectParameterization(np, nz), theta0, options.ic, options.solver);
  StoreOeRefinement(oe, data, np, nz, p, res);
  return res;
}

}  // namespace vibid::sysid
