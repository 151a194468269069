#include "vibid/sysid/poly_model.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>

#include "vibid/common/error.hpp"
#include "vibid/numerics/polynomial.hpp"

namespace vibid::sysid {

const char* StructureName(Structure s) {
  switch (s) {
    case Structure::kArx: return "arx";
    case Structure::kArmax: return "armax";
    case Structure::kOe: return "oe";
    case Structure::kBj: return "bj";
  }
  return "arx";
}

Structure ParseStructure(const std::string& name) {
  if (name == "arx") return Structure::kArx;
  if (name == "armax") return Structure::kArmax;
  if (name == "oe") return Structure::kOe;
  if (name == "bj") return Structure::kBj;
  throw InputError("unknown model structure '" + name + "' (known: arx, armax, oe, bj)");
}

void ValidateOrders(Structure s, const PolyOrders& o, Eigen::Index samples) {
  Require(o.na >= 0 && o.nc >= 0 && o.nd >= 0 && o.nf >= 0, "orders must be >= 0");
  Require(o.nb >= 1, "nb must be at least 1 (B needs a coefficient)");
  Require(o.nk >= 0, "nk (input delay) must be >= 0");
  const char* name = StructureName(s);
  switch (s) {
    case Structure::kArx:
      Require(o.nc == 0 && o.nd == 0 && o.nf == 0, "arx takes na, nb, nk only");
      break;
    case Structure::kArmax:
      Require(o.nd == 0 && o.nf == 0, "armax takes na, nb, nc, nk only");
      break;
    case Structure::kOe:
      Require(o.na == 0 && o.nc == 0 && o.nd == 0, "oe takes nb, nf, nk only");
      break;
    case Structure::kBj: Require(o.na == 0, "bj takes nb, nc, nd, nf, nk only"); break;
  }
  const Eigen::Index lag = std::max<Eigen::Index>({o.na, o.nc, o.nd, o.nf, o.nk + o.nb - 1});
  const Eigen::Index rows = samples - lag;
  Require(rows > o.Parameters(), std::string("orders too high for the data: ") + name + " with " +
                                     std::to_string(o.Parameters()) +
                                     " parameters and lags up to " + std::to_string(lag) +
                                     " needs more than " + std::to_string(o.Parameters() + lag) +
                                     " samples, the record has " + std::to_string(samples));
}

Eigen::VectorXd PolyModel::Parameters() const {
  Eigen::VectorXd t(orders.Parameters());
  Eigen::Index i = 0;
  t.segment(i, orders.na) = a.segment(1, orders.na);
  i += orders.na;
  t.segment(i, orders.nb) = b.segment(orders.nk, orders.nb);
  i += orders.nb;
  t.segment(i, orders.nc) = c.segment(1, orders.nc);
  i += orders.nc;
  t.segment(i, orders.nd) = d.segment(1, orders.nd);
  i += orders.nd;
  t.segment(i, orders.nf) = f.segment(1, orders.nf);
  return t;
}

void PolyModel::SetParameters(Eigen::Ref<const Eigen::VectorXd> theta) {
  auto monic = [&](Eigen::Index start, int n) {
    Eigen::VectorXd p(n + 1);
    p[0] = 1.0;
    p.tail(n) = theta.segment(start, n);
    return p;
  };
  Eigen::Index i = 0;
  a = monic(i, orders.na);
  i += orders.na;
  b = Eigen::VectorXd::Zero(orders.nk + orders.nb);
  b.tail(orders.nb) = theta.segment(i, orders.nb);
  i += orders.nb;
  c = monic(i, orders.nc);
  i += orders.nc;
  d = monic(i, orders.nd);
  i += orders.nd;
  f = monic(i, orders.nf);
}

Eigen::VectorXd SimulatePoly(const PolyModel& m, Eigen::Ref<const Eigen::VectorXd> u) {
  return numerics::Filter(m.b, numerics::MultiplyPolynomials(m.a, m.f), u);
}

Eigen::VectorXd PredictionErrors(const PolyModel& m, const IoData& data) {
  const Eigen::VectorXd v =
      numerics::Filter(m.a, Eigen::VectorXd::Ones(1), data.y) - numerics::Filter(m.b, m.f, data.u);
  return numerics::Filter(m.d, m.c, v);
}

Eigen::VectorXd PredictKStep(const PolyModel& m, const IoData& data, int k) {
  Require(k >= 1, "prediction horizon must be at least 1 sample");
  Eigen::VectorXd impulse = Eigen::VectorXd::Zero(k);
  impulse[0] = 1.0;
  const Eigen::VectorXd hk =
      numerics::Filter(m.c, numerics::MultiplyPolynomials(m.a, m.d), impulse);
  const Eigen::VectorXd from_y = numerics::Filter(
      numerics::MultiplyPolynomials(hk, numerics::MultiplyPolynomials(m.a, m.d)), m.c, data.y);
  const Eigen::VectorXd from_u =
      numerics::Filter(numerics::MultiplyPolynomials(hk, numerics::MultiplyPolynomials(m.d, m.b)),
                       numerics::MultiplyPolynomials(m.c, m.f), data.u);
  return data.y - from_y + from_u;
}

ArxResult EstimateArx(const IoData& data, const PolyOrders& orders) {
  ValidateOrders(Structure::kArx, orders, data.samples());
  const int na = orders.na;
  const int nb = orders.nb;
  const int nk = orders.nk;
  const Eigen::Index n = data.samples();
  const Eigen::Index t0 = std::max<Eigen::Index>(na, nk + nb - 1);
  const Eigen::Index rows = n - t0;
  const Eigen::Index p = na + nb;
  Eigen::MatrixXd phi(rows, p);
  for (Eigen::Index r = 0; r < rows; ++r) {
    const Eigen::Index t = t0 + r;
    for (int i = 0; i < na; ++i) phi(r, i) = -data.y[t - 1 - i];
    for (int j = 0; j < nb; ++j) phi(r, na + j) = data.u[t - nk - j];
  }
  const Eigen::VectorXd target = data.y.tail(rows);

  // Persistent excitation of the input for nb coefficients: its own lagged block must have full
  // rank.
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr_u(phi.rightCols(nb));
  Require(qr_u.rank() == nb,
          "input is not persistently exciting of order " + std::to_string(nb) +
              " (nb): its lagged copies are linearly dependent (constant or too few changes)");
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(phi);
  qr.setThreshold(1e-11);
  Require(qr.rank() == p, "regressors are linearly dependent: orders too high for the data (na=" +
                              std::to_string(na) + ", nb=" + std::to_string(nb) + "); lower them");
  const Eigen::VectorXd theta = qr.solve(target);
  const Eigen::VectorXd residual = target - phi * theta;

  ArxResult res;
  res.model.structure = Structure::kArx;
  res.model.orders = PolyOrders{na, nb, 0, 0, 0, nk};
  res.model.dt_s = data.dt_s;
  res.model.SetParameters(theta);
  res.rows_used = rows;
  res.loss = residual.squaredNorm() / static_cast<double>(rows);
  const double sigma2 =
      residual.squaredNorm() / static_cast<double>(std::max<Eigen::Index>(rows - p, 1));
  res.model.noise_variance = sigma2;
  // (ΦᵀΦ)⁻¹ = P R⁻¹ R⁻ᵀ Pᵀ from the pivoted QR factor.
  const Eigen::MatrixXd r_factor = qr.matrixR().topLeftCorner(p, p).triangularView<Eigen::Upper>();
  const Eigen::MatrixXd r_inv =
      r_factor.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(p, p));
  const Eigen::MatrixXd cov_perm = r_inv * r_inv.transpose();
  const auto& perm = qr.colsPermutation();
  res.model.covariance = sigma2 * (perm * cov_perm * perm.transpose());
  return res;
}

double Aic(double loss, int parameters, Eigen::Index samples) {
  return static_cast<double>(samples) * std::log(loss) + 2.0 * parameters;
}

double Fpe(double loss, int parameters, Eigen::Index samples) {
  const double ratio = static_cast<double>(parameters) / static_cast<double>(samples);
  return loss * (1.0 + ratio) / (1.0 - ratio);
}

OrderSelection SelectArxOrder(const IoData& data, int n_min, int n_max, int nk,
                              OrderCriterion criterion) {
  Require(n_min >= 1 && n_max >= n_min, "order range must satisfy 1 <= min <= max");
  OrderSelection sel;
  for (int n = n_min; n <= n_max; ++n) {
    const PolyOrders o{n, n, 0, 0, 0, nk};
    const ArxResult r = EstimateArx(data, o);
    const double c = criterion == OrderCriterion::kAic ? Aic(r.loss, o.Parameters(), r.rows_used)
                                                       : Fpe(r.loss, o.Parameters(), r.rows_used);
    sel.candidates.push_back({o, r.loss, c});
    if (c < sel.candidates[sel.best].criterion) sel.best = sel.candidates.size() - 1;
  }
  return sel;
}

}  // namespace vibid::sysid
