#include "vibid/sysid/pem.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>

#include "search.hpp"
#include "vibid/common/error.hpp"
#include "vibid/numerics/polynomial.hpp"
#include "vibid/sysid/continuous.hpp"
#include "vibid/sysid/instrumental.hpp"
#include "vibid/sysid/tfest.hpp"

namespace vibid::sysid {

namespace {

/// out = sign * (v delayed by k samples, zeros shifted in), written in place (a Jacobian column).
void DelayInto(const Eigen::VectorXd& v, Eigen::Index k, double sign,
               Eigen::Ref<Eigen::VectorXd> out) {
  const Eigen::Index n = v.size();
  const Eigen::Index zeros = std::min(k, n);
  out.head(zeros).setZero();
  out.tail(n - zeros) = sign * v.head(n - zeros);
}

bool StableFilter(const Eigen::VectorXd& p) {
  return p.size() <= 1 || numerics::SpectralRadius(p) < 1.0;
}

/// Residual and Jacobian of e = D/C (A y − B/F u) for the parameter layout of PolyModel.
bool PredictionErrorJacobian(const PolyModel& base, const IoData& data,
                             const Eigen::VectorXd& theta, Eigen::VectorXd& e,
                             Eigen::MatrixXd* jac) {
  PolyModel m = base;
  m.SetParameters(theta);
  if (!StableFilter(m.c) || !StableFilter(m.f)) return false;
  const PolyOrders& o = m.orders;
  const Eigen::VectorXd one = Eigen::VectorXd::Ones(1);
  // u/F serves twice: x = B (u/F), and the B columns' input D/(CF) u = (D/C)(u/F). One recursion
  // through F instead of two (for OE, D/C = 1 and the B columns take u/F as it is).
  const Eigen::VectorXd u_over_f = numerics::Filter(one, m.f, data.u);
  const Eigen::VectorXd x = numerics::Filter(m.b, one, u_over_f);
  const Eigen::VectorXd v = numerics::Filter(m.a, one, data.y) - x;
  e = numerics::Filter(m.d, m.c, v);
  if (jac == nullptr) return true;
  const Eigen::Index n = data.samples();
  jac->resize(n, o.Parameters());
  Eigen::Index col = 0;
  if (o.na > 0) {
    const Eigen::VectorXd yf = numerics::Filter(m.d, m.c, data.y);
    for (int k = 1; k <= o.na; ++k) DelayInto(yf, k, 1.0, jac->col(col++));
  }
  const Eigen::VectorXd uf = numerics::Filter(m.d, m.c, u_over_f);
  for (int k = 0; k < o.nb; ++k) DelayInto(uf, o.nk + k, -1.0, jac->col(col++));
  if (o.nc > 0) {
    const Eigen::VectorXd ef = numerics::Filter(one, m.c, e);
    for (int k = 1; k <= o.nc; ++k) DelayInto(ef, k, -1.0, jac->col(col++));
  }
  if (o.nd > 0) {
    const Eigen::VectorXd vf = numerics::Filter(one, m.c, v);
    for (int k = 1; k <= o.nd; ++k) DelayInto(vf, k, 1.0, jac->col(col++));
  }
  if (o.nf > 0) {
    const Eigen::VectorXd xf = numerics::Filter(m.d, numerics::MultiplyPolynomials(m.c, m.f), x);
    for (int k = 1; k <= o.nf; ++k) DelayInto(xf, k, 1.0, jac->col(col++));
  }
  return true;
}

/// Hannan–Rissanen: innovations from a long AR fit of `signal` (or an ARX fit when `input` is
/// given), then least squares of signal on its own lags, the input lags and the innovation lags.
/// Returns [a1..ana, b.., c1..cnc] in that order.
Eigen::VectorXd HannanRissanen(const Eigen::VectorXd& signal, const Eigen::VectorXd* input, int na,
                               int nb, int nk, int nc) {
  const Eigen::Index n = signal.size();
  const int long_order =
      static_cast<int>(std::min<Eigen::Index>(std::max(20, 3 * (na + nc)), n / 10));
  Eigen::VectorXd innovations = signal;
  if (long_order >= 1) {
    const Eigen::Index t0 = long_order + (input != nullptr ? nk + long_order : 0);
    const Eigen::Index rows = n - t0;
    const int cols = long_order + (input != nullptr ? long_order : 0);
    if (rows > 2 * cols) {
      Eigen::MatrixXd phi(rows, cols);
      for (Eigen::Index r = 0; r < rows; ++r) {
        const Eigen::Index t = t0 + r;
        for (int i = 0; i < long_order; ++i) phi(r, i) = -signal[t - 1 - i];
        if (input != nullptr) {
          for (int j = 0; j < long_order; ++j) phi(r, long_order + j) = (*input)[t - nk - j];
        }
      }
      const Eigen::VectorXd th = phi.colPivHouseholderQr().solve(signal.tail(rows));
      innovations = Eigen::VectorXd::Zero(n);
      innovations.tail(rows) = signal.tail(rows) - phi * th;
    }
  }
  const int nbu = input != nullptr ? nb : 0;
  const Eigen::Index t0 =
      std::max<Eigen::Index>({na, nc, input != nullptr ? nk + nb - 1 : 0}) + long_order;
  const Eigen::Index rows = n - t0;
  const int p = na + nbu + nc;
  Eigen::MatrixXd phi(rows, p);
  for (Eigen::Index r = 0; r < rows; ++r) {
    const Eigen::Index t = t0 + r;
    for (int i = 0; i < na; ++i) phi(r, i) = -signal[t - 1 - i];
    for (int j = 0; j < nbu; ++j) phi(r, na + j) = (*input)[t - nk - j];
    for (int i = 0; i < nc; ++i) phi(r, na + nbu + i) = innovations[t - 1 - i];
  }
  return phi.colPivHouseholderQr().solve(signal.tail(rows));
}

Eigen::VectorXd Monic(const Eigen::VectorXd& tail) {
  Eigen::VectorXd p(tail.size() + 1);
  p[0] = 1.0;
  p.tail(tail.size()) = tail;
  return p;
}

// At high sample rates the poles crowd near z = 1: the lagged regressors y(t−1) … y(t−nf) are
// nearly equal, and y(t−1) nearly equals the target y(t), so ZᵀΦ is singular to working precision.
// The IV regressions are therefore written in backward differences (Δs(t) = s(t) − s(t−1), the
// δ-operator basis): F(q) = Δⁿ + Σₖ gₖ Δᵏ q^−(n−k) and B(q) = Σₖ hₖ Δᵏ q^−nk, so that
//   Δⁿ y(t) = −Σₖ gₖ Δᵏ y(t − n + k) + Σₖ hₖ Δᵏ u(t − nk) + e(t),
// whose target and columns are of comparable size and far from collinear. The IV solution does
// not depend on the basis; g and h are mapped back to F and B afterwards.

/// Columns k = 0..order of d: Δᵏ s, with the samples before s's start taken as zero.
void Differences(const Eigen::VectorXd& s, int order, Eigen::MatrixXd& d) {
  const Eigen::Index n = s.size();
  d.resize(n, order + 1);
  d.col(0) = s;
  for (int k = 1; k <= order; ++k) {
    d(0, k) = d(0, k - 1);
    d.col(k).tail(n - 1) = d.col(k - 1).tail(n - 1) - d.col(k - 1).head(n - 1);
  }
}

/// Columns [col, col + count) of out, row r ↔ t = t0 + r. kDenominator: sign · Δᵏ s(t − count + k)
/// (the F block); kNumerator: sign · Δᵏ s(t − lag) (the B block and the delayed-input instruments).
enum class Block { kDenominator, kNumerator };
void FillDifferences(const Eigen::MatrixXd& d, Block block, double sign, Eigen::Index lag,
                     Eigen::Index t0, Eigen::Index col, int count,
                     Eigen::Ref<Eigen::MatrixXd> out) {
  const Eigen::Index rows = out.rows();
  for (int k = 0; k < count; ++k) {
    const Eigen::Index shift = block == Block::kDenominator ? count - k : lag;
    out.col(col + k) = sign * d.col(k).segment(t0 - shift, rows);
  }
}

/// (1 − q⁻¹)ᵏ as coefficients of q⁰, q⁻¹, …
Eigen::VectorXd DifferencePower(int k) {
  Eigen::VectorXd p = Eigen::VectorXd::Ones(1);
  for (int i = 0; i < k; ++i) p = numerics::MultiplyPolynomials(p, Eigen::Vector2d(1.0, -1.0));
  return p;
}

/// F = Δⁿ + Σₖ gₖ Δᵏ q^−(n−k), monic, as coefficients of q⁰ … q⁻ⁿ.
Eigen::VectorXd DenominatorFromDifferences(Eigen::Ref<const Eigen::VectorXd> g) {
  const int n = static_cast<int>(g.size());
  Eigen::VectorXd f = DifferencePower(n);
  for (int k = 0; k < n; ++k) f.segment(n - k, k + 1) += g[k] * DifferencePower(k);
  return f;
}

/// B's coefficients of q^−nk … q^−(nk+nb−1) from h: Σₖ hₖ Δᵏ q^−nk.
Eigen::VectorXd NumeratorFromDifferences(Eigen::Ref<const Eigen::VectorXd> h) {
  const Eigen::Index nb = h.size();
  Eigen::VectorXd b = Eigen::VectorXd::Zero(nb);
  for (int k = 0; k < nb; ++k) b.head(k + 1) += h[k] * DifferencePower(k);
  return b;
}

// The basic IV estimate with delayed inputs as instruments: consistent for any noise independent of
// u (ARX is not when the noise is not equation error, badly so at high sample rates, where A(q)
// weights the error like a high-pass). False when the record is too short or ZᵀΦ is singular.
bool BasicIv(const IoData& data, const PolyOrders& orders, Eigen::Index t0, Eigen::VectorXd& f,
             Eigen::VectorXd& b) {
  const int nf = orders.nf;
  const int nb = orders.nb;
  const int nk = orders.nk;
  const Eigen::Index n = data.samples();
  const Eigen::Index lag0 = nk + nb + nf - 1;
  const Eigen::Index s0 = std::max<Eigen::Index>(t0, lag0);
  const Eigen::Index m = n - s0;
  if (!(nf > 0 && m > 2 * (nf + nb))) return false;
  Eigen::MatrixXd phi(m, nf + nb);
  Eigen::MatrixXd zeta(m, nf + nb);
  Eigen::MatrixXd dy;
  Eigen::MatrixXd du;
  Differences(data.y, nf, dy);
  Differences(data.u, std::max(nf, nb), du);
  FillDifferences(dy, Block::kDenominator, -1.0, 0, s0, 0, nf, phi);
  FillDifferences(du, Block::kNumerator, 1.0, nk, s0, nf, nb, phi);
  FillDifferences(du, Block::kNumerator, 1.0, nk + nb, s0, 0, nf, zeta);
  zeta.rightCols(nb) = phi.rightCols(nb);
  Eigen::VectorXd th;
  if (!SolveInstrumental(zeta, phi, dy.col(nf).tail(m), th)) return false;
  f = numerics::StabilizeDiscrete(DenominatorFromDifferences(th.head(nf)));
  b = Eigen::VectorXd::Zero(nk + nb);
  b.tail(nb) = NumeratorFromDifferences(th.tail(nb));
  return true;
}

// Simplified refined IV (Young): prefilter y, u and the instruments by 1/F̂ and use the noise-free
// output of the current model as instruments. At a fixed point F̂ = F the IV equations read
// Σ ζ(t) (y(t) − B/F u(t)) = 0 with ζ = −∂ŷ/∂θ: the OE criterion's stationarity condition, so the
// search that follows only confirms it. True when the relative change fell below `tolerance`.
bool RefineIv(const IoData& data, const PolyOrders& orders, Eigen::Index t0, double tolerance,
              Eigen::VectorXd& f, Eigen::VectorXd& b) {
  const int nf = orders.nf;
  const int nb = orders.nb;
  const int nk = orders.nk;
  const Eigen::Index rows = data.samples() - t0;
  const Eigen::VectorXd one = Eigen::VectorXd::Ones(1);
  Eigen::VectorXd previous;
  // The regressor matrices are allocated once: fresh megabyte-sized ones per pass cost page faults.
  Eigen::MatrixXd phi(rows, nf + nb);
  Eigen::MatrixXd zeta(rows, nf + nb);
  Eigen::MatrixXd dy;
  Eigen::MatrixXd dx;
  Eigen::MatrixXd du;
  Eigen::VectorXd yf;
  Eigen::VectorXd uf;
  for (int pass = 0; pass < 20 && nf > 0; ++pass) {
    numerics::FilterPair(one, f, data.y, data.u, yf, uf);
    const Eigen::VectorXd x = numerics::Filter(b, one, uf);  // B/F u: one recursion fewer
    const Eigen::VectorXd xf = numerics::Filter(one, f, x);
    Differences(yf, nf, dy);
    Differences(xf, nf, dx);
    Differences(uf, nb, du);
    FillDifferences(dy, Block::kDenominator, -1.0, 0, t0, 0, nf, phi);
    FillDifferences(dx, Block::kDenominator, -1.0, 0, t0, 0, nf, zeta);
    FillDifferences(du, Block::kNumerator, 1.0, nk, t0, nf, nb, phi);
    zeta.rightCols(nb) = phi.rightCols(nb);
    Eigen::VectorXd th;
    if (!SolveInstrumental(zeta, phi, dy.col(nf).tail(rows), th)) break;
    f = numerics::StabilizeDiscrete(DenominatorFromDifferences(th.head(nf)));
    b = Eigen::VectorXd::Zero(nk + nb);
    b.tail(nb) = NumeratorFromDifferences(th.tail(nb));
    Eigen::VectorXd current(nf + nb);
    current << f.tail(nf), b.tail(nb);
    if (previous.size() == current.size() &&
        (current - previous).norm() <= tolerance * current.norm())
      return true;
    previous = current;
  }
  return false;
}

/// B and F from the basic IV, or from ARX when the basic IV has no solution.
void IvStart(const IoData& data, const PolyOrders& orders, Eigen::Index t0, Eigen::VectorXd& f,
             Eigen::VectorXd& b) {
  if (BasicIv(data, orders, t0, f, b)) return;
  const ArxResult arx = EstimateArx(data, PolyOrders{orders.nf, orders.nb, 0, 0, 0, orders.nk});
  f = numerics::StabilizeDiscrete(arx.model.a);
  b = arx.model.b;
}

PolyModel RefinedIvEstimate(const IoData& data, const PolyOrders& orders, double tolerance,
                            bool& converged) {
  const Eigen::Index t0 = std::max<Eigen::Index>(orders.nf, orders.nk + orders.nb - 1);
  // The passes far from the fixed point only need to bring F̂ near it: on a long record they run on
  // its first quarter, and the passes on the whole record then converge to the whole record's
  // fixed point (the estimate does not depend on how the start was found, only the pass count).
  const Eigen::Index head = data.samples() / 4;
  Eigen::VectorXd f;
  Eigen::VectorXd b;
  converged = false;
  if (head >= 500 * (orders.nf + orders.nb)) {
    const IoData first = Slice(data, 0, head);
    IvStart(first, orders, t0, f, b);
    if (RefineIv(first, orders, t0, 1e-3, f, b)) {
      converged = RefineIv(data, orders, t0, tolerance, f, b);
    }
  }
  if (!converged) {
    IvStart(data, orders, t0, f, b);
    converged = RefineIv(data, orders, t0, tolerance, f, b);
  }
  PolyModel m;
  m.structure = Structure::kOe;
  m.orders = PolyOrders{0, orders.nb, 0, 0, orders.nf, orders.nk};
  m.dt_s = data.dt_s;
  m.b = b;
  m.f = f;
  return m;
}

}  // namespace

PolyModel EstimateOeIv(const IoData& data, const PolyOrders& orders, double tolerance) {
  bool converged = false;
  return RefinedIvEstimate(data, orders, tolerance, converged);
}

namespace {

/// The refined-IV estimate when its passes converge. When they do not and the orders are those of a
/// sampled continuous system (nk = 1, nb = nf), the better (by simulation error) of it and the ZOH
/// image of an SRIVC continuous-time estimate, whose regressors are time derivatives rather than
/// lags.
PolyModel OeStart(const IoData& data, const PolyOrders& orders, std::string& name) {
  // Only a start: the search polishes it, so the IV passes stop at a 1e-6 relative change.
  bool converged = false;
  PolyModel best = RefinedIvEstimate(data, orders, 1e-6, converged);
  name = "instrumental-variable";
  if (converged || orders.nk != 1 || orders.nb != orders.nf || orders.nf < 1 || orders.nf > 20)
    return best;
  TfestOptions ct;
  ct.np = orders.nf;
  ct.nz = orders.nf - 1;
  ct.refine = false;
  if (data.samples() < 10 * (ct.np + ct.nz + 1)) return best;
  const TfestResult r = EstimateTf(data, ct);
  if (r.tf.den.size() != orders.nf + 1) return best;
  const DiscreteTf d = C2dZoh(r.tf, data.dt_s);
  PolyModel candidate = best;
  candidate.f = numerics::StabilizeDiscrete(d.den);
  candidate.b = Eigen::VectorXd::Zero(orders.nk + orders.nb);
  candidate.b.tail(orders.nb) = d.num.tail(orders.nb);
  const double err_best = (data.y - SimulatePoly(best, data.u)).squaredNorm();
  const double err_ct = (data.y - SimulatePoly(candidate, data.u)).squaredNorm();
  if (std::isfinite(err_ct) && !(err_ct >= err_best)) {
    name = "continuous-time srivc (zoh)";
    return candidate;
  }
  return best;
}

}  // namespace

PemResult EstimatePem(const IoData& data, Structure structure, const PolyOrders& orders,
                      const numerics::SolverOptions& options) {
  options.Validate();
  ValidateOrders(structure, orders, data.samples());
  PemResult res;
  if (structure == Structure::kArx) {
    const ArxResult arx = EstimateArx(data, orders);
    res.model = arx.model;
    res.initialization = "least-squares";
    res.summary.termination = numerics::TerminationType::kFunctionTolerance;
    res.summary.initial_cost = res.summary.final_cost = arx.loss;
    res.summary.message = "linear least squares (closed form)";
    return res;
  }

  PolyModel start;
  start.structure = structure;
  start.orders = orders;
  start.dt_s = data.dt_s;
  switch (structure) {
    case Structure::kArmax: {
      // A stable start for ARMAX: regress y on its lags, the input and the innovations.
      const Eigen::VectorXd th =
          HannanRissanen(data.y, &data.u, orders.na, orders.nb, orders.nk, orders.nc);
      Eigen::VectorXd theta(orders.Parameters());
      theta << th;
      start.SetParameters(theta);
      start.c = numerics::StabilizeDiscrete(start.c);
      res.initialization = "hannan-rissanen";
      break;
    }
    case Structure::kOe: {
      const PolyModel iv = OeStart(data, orders, res.initialization);
      start.b = iv.b;
      start.f = iv.f;
      break;
    }
    case Structure::kBj: {
      const PolyModel iv =
          OeStart(data, PolyOrders{0, orders.nb, 0, 0, orders.nf, orders.nk}, res.initialization);
      start.b = iv.b;
      start.f = iv.f;
      const Eigen::VectorXd w = data.y - numerics::Filter(iv.b, iv.f, data.u);
      // Noise model C/D: an ARMA fit of the output error, D from its AR part, C from the MA part.
      const Eigen::VectorXd th = HannanRissanen(w, nullptr, orders.nd, 0, 0, orders.nc);
      start.d = numerics::StabilizeDiscrete(Monic(th.head(orders.nd)));
      start.c = numerics::StabilizeDiscrete(Monic(th.tail(orders.nc)));
      res.initialization += " + hannan-rissanen";
      break;
    }
    case Structure::kArx: break;
  }

  Eigen::VectorXd theta = start.Parameters();
  const numerics::ResidualFunction fn = [&](const Eigen::VectorXd& th, Eigen::VectorXd& r,
                                            Eigen::MatrixXd* j) {
    return PredictionErrorJacobian(start, data, th, r, j);
  };
  numerics::Solution solution;
  res.summary = MinimizePredictionError(fn, theta, options, solution);
  res.model = start;
  res.model.SetParameters(theta);
  Eigen::VectorXd& e = solution.residuals;
  if (e.size() == data.samples()) {
    res.model.covariance = numerics::CovarianceFromFactor(solution.r_factor, e);
  } else {
    PredictionErrorJacobian(start, data, theta, e, nullptr);
  }
  res.model.noise_variance = e.squaredNorm() / static_cast<double>(std::max<Eigen::Index>(
                                                   e.size() - orders.Parameters(), 1));
  return res;
}

}  // namespace vibid::sysid
