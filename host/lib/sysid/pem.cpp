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
  const Eigen::VectorXd x = numerics::Filter(m.b, m.f, data.u);
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
  const Eigen::VectorXd cf = numerics::MultiplyPolynomials(m.c, m.f);
  const Eigen::VectorXd uf = numerics::Filter(m.d, cf, data.u);
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
    const Eigen::VectorXd xf = numerics::Filter(m.d, cf, x);
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

// ARX is biased when the noise is not equation error (badly so at high sample rates, where A(q)
// weights the error like a high-pass). The basic IV estimate with delayed inputs as instruments
// is consistent for any noise independent of u: it replaces f, b when it simulates better.
void PreferBasicIv(const IoData& data, const PolyOrders& orders, Eigen::Index t0,
                   Eigen::VectorXd& f, Eigen::VectorXd& b) {
  const int nf = orders.nf;
  const int nb = orders.nb;
  const int nk = orders.nk;
  const Eigen::Index n = data.samples();
  const Eigen::Index lag0 = nk + nb + nf - 1;
  const Eigen::Index s0 = std::max<Eigen::Index>(t0, lag0);
  const Eigen::Index m = n - s0;
  if (!(nf > 0 && m > 2 * (nf + nb))) return;
  Eigen::MatrixXd phi(m, nf + nb);
  Eigen::MatrixXd zeta(m, nf + nb);
  for (Eigen::Index r = 0; r < m; ++r) {
    const Eigen::Index t = s0 + r;
    for (int i = 0; i < nf; ++i) {
      phi(r, i) = -data.y[t - 1 - i];
      zeta(r, i) = data.u[t - nk - nb - i];
    }
    for (int j = 0; j < nb; ++j) phi(r, nf + j) = zeta(r, nf + j) = data.u[t - nk - j];
  }
  Eigen::VectorXd th;
  if (!SolveInstrumental(zeta, phi, data.y.tail(m), th)) return;
  const Eigen::VectorXd f_iv = numerics::StabilizeDiscrete(Monic(th.head(nf)));
  Eigen::VectorXd b_iv = Eigen::VectorXd::Zero(nk + nb);
  b_iv.tail(nb) = th.tail(nb);
  const double err_iv = (data.y - numerics::Filter(b_iv, f_iv, data.u)).squaredNorm();
  const double err_arx = (data.y - numerics::Filter(b, f, data.u)).squaredNorm();
  if (std::isfinite(err_iv) && err_iv < err_arx) {
    f = f_iv;
    b = b_iv;
  }
}

// Simplified refined IV (Young): prefilter y, u and the instruments by 1/F̂ and use the noise-free
// output of the current model as instruments; a fixed point of the iteration is consistent and
// close to the OE optimum, so the search that follows only polishes.
void RefineIv(const IoData& data, const PolyOrders& orders, Eigen::Index t0, double tolerance,
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
  for (int pass = 0; pass < 20 && nf > 0; ++pass) {
    const Eigen::VectorXd x = numerics::Filter(b, f, data.u);
    const Eigen::VectorXd yf = numerics::Filter(one, f, data.y);
    const Eigen::VectorXd uf = numerics::Filter(one, f, data.u);
    const Eigen::VectorXd xf = numerics::Filter(one, f, x);
    for (Eigen::Index r = 0; r < rows; ++r) {
      const Eigen::Index t = t0 + r;
      for (int i = 0; i < nf; ++i) {
        phi(r, i) = -yf[t - 1 - i];
        zeta(r, i) = -xf[t - 1 - i];
      }
      for (int j = 0; j < nb; ++j) phi(r, nf + j) = zeta(r, nf + j) = uf[t - nk - j];
    }
    Eigen::VectorXd th;
    if (!SolveInstrumental(zeta, phi, yf.tail(rows), th)) break;
    f = numerics::StabilizeDiscrete(Monic(th.head(nf)));
    b = Eigen::VectorXd::Zero(nk + nb);
    b.tail(nb) = th.tail(nb);
    Eigen::VectorXd current(nf + nb);
    current << f.tail(nf), th.tail(nb);
    if (previous.size() == current.size() &&
        (current - previous).norm() <= tolerance * current.norm())
      break;
    previous = current;
  }
}

}  // namespace

PolyModel EstimateOeIv(const IoData& data, const PolyOrders& orders, double tolerance) {
  const PolyOrders arx_orders{orders.nf, orders.nb, 0, 0, 0, orders.nk};
  const ArxResult arx = EstimateArx(data, arx_orders);
  Eigen::VectorXd f = numerics::StabilizeDiscrete(arx.model.a);
  Eigen::VectorXd b = arx.model.b;
  const Eigen::Index t0 = std::max<Eigen::Index>(orders.nf, orders.nk + orders.nb - 1);
  PreferBasicIv(data, orders, t0, f, b);
  RefineIv(data, orders, t0, tolerance, f, b);
  PolyModel m;
  m.structure = Structure::kOe;
  m.orders = PolyOrders{0, orders.nb, 0, 0, orders.nf, orders.nk};
  m.dt_s = data.dt_s;
  m.b = b;
  m.f = f;
  return m;
}

namespace {

/// The better (by simulation error) of the refined-IV start and, when the orders are those of a
/// sampled continuous system (nk = 1, nb = nf), the ZOH image of an SRIVC continuous-time estimate.
/// At high sample rates the poles crowd near z = 1 and the q⁻¹ regressors become nearly collinear
/// (ZᵀΦ then has a condition number near 1/eps); the continuous-time route does not suffer from it.
PolyModel OeStart(const IoData& data, const PolyOrders& orders, std::string& name) {
  // Only a start: the search polishes it, so the IV passes stop at a 1e-6 relative change.
  PolyModel best = EstimateOeIv(data, orders, 1e-6);
  name = "instrumental-variable";
  if (orders.nk != 1 || orders.nb != orders.nf || orders.nf < 1 || orders.nf > 20) return best;
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
  Eigen::MatrixXd jac;
  res.summary = MinimizePredictionError(fn, theta, options, jac);
  res.model = start;
  res.model.SetParameters(theta);
  Eigen::VectorXd e;
  PredictionErrorJacobian(start, data, theta, e, nullptr);
  if (jac.rows() == e.size()) {
    res.model.covariance = numerics::CovarianceFromJacobian(jac, e);
  }
  res.model.noise_variance = e.squaredNorm() / static_cast<double>(std::max<Eigen::Index>(
                                                   e.size() - orders.Parameters(), 1));
  return res;
}

}  // namespace vibid::sysid
