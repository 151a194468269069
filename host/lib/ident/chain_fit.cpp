// Physical identification of a chain from its modal data (methods §12; chain_fit.hpp).
#include "vibid/ident/chain_fit.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <functional>
#include <limits>

#include "vibid/common/error.hpp"
#include "vibid/model/modal.hpp"

namespace vibid::ident {

namespace {

using cd = std::complex<double>;

// y = [omega, zeta, phi...] of a pole and the residues q_j = phi_j phi_p (complex, as measured);
// the projection on the driving point's phase makes a real shape of them.
Eigen::VectorXd QuantitiesOf(const cd& lambda, const Eigen::VectorXcd& q, Eigen::Index p) {
  const Eigen::Index n = q.size();
  Eigen::VectorXd y(2 + n);
  const double w = std::abs(lambda);
  y[0] = w;
  y[1] = -lambda.real() / w;
  const double qp = std::abs(q[p]);
  const double phi_p = std::sqrt(qp);
  for (Eigen::Index j = 0; j < n; ++j)
    y[2 + j] = j == p ? phi_p : std::real(q[j] * std::conj(q[p])) / qp / phi_p;
  return y;
}

// Structure pole from omega and zeta.
cd Pole(double omega, double zeta) {
  return {-zeta * omega, omega * std::sqrt(std::max(0.0, 1.0 - zeta * zeta))};
}

}  // namespace

const char* ParameterSourceName(ParameterSource source) {
  switch (source) {
    case ParameterSource::kTest: return "test";
    case ParameterSource::kTestAndPrior: return "test and prior";
    case ParameterSource::kPrior: return "prior";
  }
  return "?";
}

void ChainFitOptions::Validate() const {
  Require(prior_relative_sd > 0.0 && std::isfinite(prior_relative_sd),
          "chain fit: the prior's spread must be > 0");
  Require(prior_ratio_determined > 0.0 && prior_ratio_determined < prior_ratio_from_prior &&
              prior_ratio_from_prior < 1.0,
          "chain fit: need 0 < determined ratio < prior ratio < 1");
  Require(max_ringing_left > 0.0 && max_ringing_left <= 1.0,
          "chain fit: the ringing left at a record's end must be in (0, 1]");
  Require(systematic_omega_rel >= 0.0 && systematic_zeta_rel >= 0.0 &&
              systematic_shape_rel >= 0.0 && ringing_error_per_left >= 0.0 &&
              std::isfinite(ringing_error_per_left) && std::isfinite(systematic_omega_rel) &&
              std::isfinite(systematic_zeta_rel) && std::isfinite(systematic_shape_rel),
          "chain fit: the systematic parts must be finite and >= 0");
  solver.Validate();
}

ChainModeData ChainDataOfMode(const ModalModelFit& fit, Eigen::Index mode,
                              Eigen::Index driving_point) {
  const Eigen::Index modes = fit.lambda.size();
  const Eigen::Index n = fit.residues.cols();
  Require(mode >= 0 && mode < modes, "chain data: no such mode in the modal model");
  Require(driving_point >= 0 && driving_point < n, "chain data: driving point out of range");
  // The window moved the pole by -1/tau (StoreStructurePole): the same shift maps the pole the
  // FRF shows to the structure's.
  const cd lw = fit.lambda[mode];
  const cd lt = Pole(fit.omega_rad_s[mode], fit.zeta[mode]);
  const double inv_tau = lt.real() - lw.real();
  // x = [omega_w, zeta_w, Re Q_0, Im Q_0, ...]: the pole as the FRF shows it and the residues.
  const auto map = [&](const Eigen::VectorXd& x) {
    const cd l = Pole(x[0], x[1]) + inv_tau;
    Eigen::VectorXcd q(n);
    for (Eigen::Index j = 0; j < n; ++j)
      q[j] = cd(0.0, 2.0 * l.imag()) * cd(x[2 + 2 * j], x[3 + 2 * j]) / (l * l);
    return QuantitiesOf(l, q, driving_point);
  };
  Eigen::VectorXd x(2 + 2 * n);
  x[0] = std::abs(lw);
  x[1] = -lw.real() / x[0];
  for (Eigen::Index j = 0; j < n; ++j) {
    x[2 + 2 * j] = fit.residues(mode, j).real();
    x[3 + 2 * j] = fit.residues(mode, j).imag();
  }
  ChainModeData out;
  out.values = map(x);
  Require(std::isfinite(out.values[2 + driving_point]) && out.values[2 + driving_point] > 0.0,
          "chain data: the driving-point residue gives no positive phi_p^2");
  if (fit.ringing_terms_dropped) {
    out.no_covariance =
        "the modal model left out the pretrigger's ringing terms, so its covariance misses them";
    return out;
  }
  if (fit.covariance.rows() == 0) {
    out.no_covariance = "the modal model has no covariance";
    return out;
  }
  // Jacobian of the map by central differences, then onto the modal model's parameters: omega and
  // zeta of the mode, and each response's residue R, plus the ringing term S when there is one
  // (the stored residue is R + S exp(j omega_d t_p); the phase's own dependence on the pole is of
  // second order, as in ShapeRatioSd).
  Eigen::MatrixXd jx(2 + n, x.size());
  for (Eigen::Index c = 0; c < x.size(); ++c) {
    const double h = 1e-6 * std::max(std::abs(x[c]), c < 2 ? 1e-3 : x.segment(2, 2 * n).norm());
    Eigen::VectorXd a = x, b = x;
    a[c] += h;
    b[c] -= h;
    jx.col(c) = (map(a) - map(b)) / (2.0 * h);
  }
  const Eigen::Index per = fit.per_response;
  const bool ringing = per > 2 * modes + 2;
  const cd e = std::polar(1.0, lw.imag() * fit.pretrigger_s);
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(2 + n, fit.covariance.rows());
  g.col(2 * mode) = jx.col(0);
  g.col(2 * mode + 1) = jx.col(1);
  for (Eigen::Index o = 0; o < n; ++o) {
    const Eigen::Index at = 2 * modes + o * per + 2 * mode;
    const Eigen::VectorXd dre = jx.col(2 + 2 * o), dim = jx.col(3 + 2 * o);
    g.col(at) = dre;
    g.col(at + 1) = dim;
    if (ringing) {
      g.col(at + 2 * modes) = dre * e.real() + dim * e.imag();
      g.col(at + 2 * modes + 1) = -dre * e.imag() + dim * e.real();
    }
  }
  for (Eigen::Index r = 0; r < g.rows(); ++r) {
    if (!std::isfinite(fit.Variance(g.row(r).transpose()))) {
      out.no_covariance = "the modal model does not determine this mode's pole or residues";
      return out;
    }
  }
  out.covariance = g * fit.covariance * g.transpose();
  return out;
}

std::vector<Eigen::VectorXd> ChainModalQuantities(const model::Model& chain,
                                                  Eigen::Index driving_point) {
  const Eigen::Index n = chain.m_kg.rows();
  Require(driving_point >= 0 && driving_point < n, "chain quantities: driving point out of range");
  const Eigen::MatrixXd minv = chain.m_kg.inverse();
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  a.topRightCorner(n, n).setIdentity();
  a.bottomLeftCorner(n, n) = -minv * chain.k_n_per_m;
  a.bottomRightCorner(n, n) = -minv * chain.c_ns_per_m;
  Eigen::VectorXd b = Eigen::VectorXd::Zero(2 * n);
  b.tail(n) = minv.col(driving_point);
  const Eigen::EigenSolver<Eigen::MatrixXd> es(a);
  Require(es.info() == Eigen::Success, "chain quantities: the state matrix has no eigenvalues");
  const Eigen::MatrixXcd v = es.eigenvectors();
  const Eigen::VectorXcd wb = v.partialPivLu().solve(b.cast<cd>());
  std::vector<Eigen::Index> upper;
  for (Eigen::Index i = 0; i < 2 * n; ++i) {
    const cd l = es.eigenvalues()[i];
    if (l.imag() > 1e-9 * std::abs(l)) upper.push_back(i);
  }
  Require(static_cast<Eigen::Index>(upper.size()) == n,
          "chain quantities: a mode of the chain does not oscillate");
  std::sort(upper.begin(), upper.end(), [&](Eigen::Index i, Eigen::Index j) {
    return std::abs(es.eigenvalues()[i]) < std::abs(es.eigenvalues()[j]);
  });
  std::vector<Eigen::VectorXd> out;
  for (const Eigen::Index i : upper) {
    const cd l = es.eigenvalues()[i];
    // Residue of x_j / F_p at the pole: (V)_{j i} (V^-1 B)_i; q_j = 2 j omega_d A_jp.
    Eigen::VectorXcd q(n);
    for (Eigen::Index j = 0; j < n; ++j) q[j] = cd(0.0, 2.0 * l.imag()) * v(j, i) * wb[i];
    out.push_back(QuantitiesOf(l, q, driving_point));
  }
  return out;
}

std::vector<Eigen::Index> MatchChainModes(const model::Model& nominal,
                                          const std::vector<double>& omega_rad_s) {
  const Eigen::VectorXd w = model::Modal(nominal).omega_rad_s;
  const auto n = static_cast<std::size_t>(w.size());
  const std::size_t k = omega_rad_s.size();
  Require(k <= n, "chain fit: the test shows " + std::to_string(k) + " modes, the chain has " +
                      std::to_string(n));
  std::vector<Eigen::Index> best, cur;
  double best_cost = std::numeric_limits<double>::infinity();
  // Every increasing choice of k of the n modes (n is small).
  std::function<void(std::size_t, double)> walk = [&](std::size_t from, double cost) {
    if (cur.size() == k) {
      if (cost < best_cost) {
        best_cost = cost;
        best = cur;
      }
      return;
    }
    for (std::size_t i = from; i + (k - cur.size()) <= n; ++i) {
      const double d = std::log(omega_rad_s[cur.size()] / w[static_cast<Eigen::Index>(i)]);
      cur.push_back(static_cast<Eigen::Index>(i));
      walk(i + 1, cost + d * d);
      cur.pop_back();
    }
  };
  walk(0, 0.0);
  return best;
}

namespace {

struct Datum {
  Eigen::Index chain_mode;
  Eigen::VectorXd y;
  Eigen::MatrixXd whiten;  // L^-1 with L L^T the covariance
};

model::Model ChainOfLog(const Eigen::VectorXd& x, Eigen::Index n) {
  return model::MakeChain(x.segment(0, n).array().exp().matrix(),
                          x.segment(n, n).array().exp().matrix(),
                          x.segment(2 * n, n).array().exp().matrix());
}

// The closed forms of methods §12 from one test with every mode, as a start: M = (Phi Phi^T)^-1
// and K, C by the diagonal convention, each kept positive (else the nominal value).
Eigen::VectorXd ClosedFormStart(const std::vector<Datum>& data, const Eigen::VectorXd& nominal_x,
                                Eigen::Index n) {
  Eigen::MatrixXd phi(n, n);
  Eigen::VectorXd om(n), ze(n);
  for (const Datum& d : data) {
    phi.col(d.chain_mode) = d.y.tail(n);
    om[d.chain_mode] = d.y[0];
    ze[d.chain_mode] = d.y[1];
  }
  const Eigen::MatrixXd m = (phi * phi.transpose()).inverse();
  const Eigen::MatrixXd k = m * phi * om.cwiseAbs2().asDiagonal() * phi.transpose() * m;
  const Eigen::MatrixXd c =
      m * phi * (2.0 * ze.cwiseProduct(om)).asDiagonal() * phi.transpose() * m;
  Eigen::VectorXd x = nominal_x;
  Eigen::VectorXd kc(n), cc(n);
  kc[n - 1] = k(n - 1, n - 1);
  cc[n - 1] = c(n - 1, n - 1);
  for (Eigen::Index i = n - 2; i >= 0; --i) {
    kc[i] = k(i, i) - kc[i + 1];
    cc[i] = c(i, i) - cc[i + 1];
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    if (m(i, i) > 0.0 && std::isfinite(m(i, i))) x[i] = std::log(m(i, i));
    if (kc[i] > 0.0 && std::isfinite(kc[i])) x[n + i] = std::log(kc[i]);
    if (cc[i] > 0.0 && std::isfinite(cc[i])) x[2 * n + i] = std::log(cc[i]);
  }
  return x;
}

}  // namespace

ChainFitResult FitChain(const model::Model& nominal, const std::vector<ChainTestModes>& tests,
                        const ChainFitOptions& options) {
  options.Validate();
  model::Validate(nominal);
  Require(nominal.m_kg.isDiagonal(), "chain fit: the nominal model needs a diagonal mass matrix");
  const Eigen::Index n = nominal.m_kg.rows();
  const Eigen::Index p = options.driving_point;
  Require(p >= 0 && p < n, "chain fit: driving point out of range");
  ChainFitResult res;
  std::vector<Datum> data;
  std::string no_covariance, zeta_withheld;
  std::vector<bool> seen(static_cast<std::size_t>(n), false);
  for (std::size_t t = 0; t < tests.size(); ++t) {
    const ChainTestModes& test = tests[t];
    Require(test.modes.size() == test.chain_mode.size(), "chain fit: a chain mode per test mode");
    std::vector<bool> in_test(static_cast<std::size_t>(n), false);
    for (std::size_t i = 0; i < test.modes.size(); ++i) {
      const ChainModeData& d = test.modes[i];
      const Eigen::Index cm = test.chain_mode[i];
      Require(cm >= 0 && cm < n, "chain fit: chain mode out of range");
      Require(!in_test[static_cast<std::size_t>(cm)],
              "chain fit: a chain mode seen twice in a test");
      Require(d.values.size() == 2 + n,
              "chain fit: each mode needs omega, zeta and " + std::to_string(n) + " shape entries");
      in_test[static_cast<std::size_t>(cm)] = true;
      seen[static_cast<std::size_t>(cm)] = true;
      Datum datum{cm, d.values, Eigen::MatrixXd()};
      Eigen::MatrixXd cov = d.covariance;
      if (cov.rows() == 2 + n && d.level_rel_var > 0.0) {
        // A level error e scales the residues by 1 + e and the shape by 1 + e / 2.
        Eigen::VectorXd g = Eigen::VectorXd::Zero(2 + n);
        g.tail(n) = 0.5 * d.values.tail(n);
        cov += d.level_rel_var * g * g.transpose();
      }
      if (cov.rows() == 2 + n) {
        // The method's own error (ChainFitOptions::systematic_*), independent of the noise.
        const double shape_scale = d.values.tail(n).cwiseAbs().maxCoeff();
        cov(0, 0) += std::pow(options.systematic_omega_rel * d.values[0], 2);
        cov(1, 1) += std::pow(options.systematic_zeta_rel * d.values[1], 2);
        for (Eigen::Index j = 0; j < n; ++j) {
          cov(2 + j, 2 + j) += std::pow(options.systematic_shape_rel * shape_scale, 2) +
                               std::pow(d.ringing_rel_sd * d.values[2 + j], 2);
        }
        cov(1, 1) += std::pow(d.ringing_rel_sd * d.values[1], 2);
      }
      if (!d.zeta_withheld.empty() && cov.rows() == 2 + n) {
        // zeta out of the weighted data: no correlation, a variance that outweighs any damper.
        const double v = cov(1, 1) * 1e12;
        cov.row(1).setZero();
        cov.col(1).setZero();
        cov(1, 1) = v;
        if (zeta_withheld.empty()) zeta_withheld = d.zeta_withheld;
      }
      Eigen::LLT<Eigen::MatrixXd> llt;
      if (cov.rows() == 2 + n) llt.compute(cov);
      if (d.covariance.rows() == 2 + n && llt.info() == Eigen::Success) {
        datum.whiten = llt.matrixL().solve(Eigen::MatrixXd::Identity(2 + n, 2 + n));
      } else {
        // No covariance: weights of the size a good test has (0.1 % on omega, 5 % on zeta, 1 % of
        // the shape), for the values only; no interval follows.
        if (no_covariance.empty())
          no_covariance = d.no_covariance.empty() ? "a mode's covariance is not positive definite"
                                                  : d.no_covariance;
        Eigen::VectorXd sd(2 + n);
        sd[0] = 1e-3 * d.values[0];
        sd[1] = 0.05 * d.values[1];
        sd.tail(n).setConstant(0.01 * d.values.tail(n).norm());
        datum.whiten = sd.cwiseInverse().asDiagonal();
      }
      data.push_back(std::move(datum));
    }
  }
  Require(!data.empty(), "chain fit: no mode to fit");
  for (Eigen::Index i = 0; i < n; ++i)
    if (seen[static_cast<std::size_t>(i)]) res.modes_seen.push_back(i);
  res.prior_used = static_cast<Eigen::Index>(res.modes_seen.size()) < n;

  // Nominal values as the start and the prior's centre; a damper the nominal model lacks starts at
  // the test's mean damping ratio on its spring and mass.
  const model::Model& nm = nominal;
  Eigen::VectorXd x0(3 * n), prior_sd = Eigen::VectorXd::Constant(3 * n, options.prior_relative_sd);
  {
    Eigen::VectorXd mk(n), kk(n), ck(n);
    mk = nm.m_kg.diagonal();
    kk[n - 1] = nm.k_n_per_m(n - 1, n - 1);
    ck[n - 1] = nm.c_ns_per_m(n - 1, n - 1);
    for (Eigen::Index i = n - 2; i >= 0; --i) {
      kk[i] = nm.k_n_per_m(i, i) - kk[i + 1];
      ck[i] = nm.c_ns_per_m(i, i) - ck[i + 1];
    }
    double zeta_mean = 0.0;
    for (const Datum& d : data) zeta_mean += d.y[1] / static_cast<double>(data.size());
    for (Eigen::Index i = 0; i < n; ++i) {
      Require(kk[i] > 0.0, "chain fit: the nominal chain needs positive springs");
      x0[i] = std::log(mk[i]);
      x0[n + i] = std::log(kk[i]);
      if (ck[i] > 0.0) {
        x0[2 * n + i] = std::log(ck[i]);
      } else {
        x0[2 * n + i] = std::log(std::max(1e-6, 2.0 * zeta_mean * std::sqrt(kk[i] * mk[i])));
        prior_sd[2 * n + i] = 1.0;
      }
    }
  }
  const Eigen::Index rows_data = static_cast<Eigen::Index>(data.size()) * (2 + n);
  const Eigen::Index rows = rows_data + (res.prior_used ? 3 * n : 0);
  const auto residual = [&](const Eigen::VectorXd& x, Eigen::VectorXd& r) {
    if (!x.allFinite() || x.maxCoeff() > 50.0 || x.minCoeff() < -50.0) return false;
    std::vector<Eigen::VectorXd> q;
    try {
      q = ChainModalQuantities(ChainOfLog(x, n), p);
    } catch (const InputError&) {
      return false;
    }
    r.resize(rows);
    for (std::size_t i = 0; i < data.size(); ++i) {
      const Datum& d = data[i];
      r.segment(static_cast<Eigen::Index>(i) * (2 + n), 2 + n) =
          d.whiten * (q[static_cast<std::size_t>(d.chain_mode)] - d.y);
    }
    if (res.prior_used) r.tail(3 * n) = (x - x0).cwiseQuotient(prior_sd);
    return r.allFinite();
  };
  const numerics::ResidualFunction fn = numerics::NumericDiff(residual, 1e-7);
  std::vector<Eigen::VectorXd> starts{x0};
  if (!res.prior_used && tests.size() >= 1) {
    // The first test with every mode gives the closed-form start.
    for (const ChainTestModes& t : tests) {
      if (static_cast<Eigen::Index>(t.modes.size()) != n) continue;
      std::vector<Datum> one;
      for (std::size_t i = 0; i < t.modes.size(); ++i)
        one.push_back({t.chain_mode[i], t.modes[i].values, Eigen::MatrixXd()});
      starts.push_back(ClosedFormStart(one, x0, n));
      break;
    }
  }
  Eigen::VectorXd best;
  numerics::Solution best_solution;
  for (const Eigen::VectorXd& s : starts) {
    Eigen::VectorXd x = s;
    numerics::Solution sol;
    const numerics::SolverSummary sum = numerics::LevenbergMarquardt(fn, x, options.solver, &sol);
    if (sol.residuals.size() == 0) continue;
    if (best.size() == 0 || sum.final_cost < res.summary.final_cost) {
      best = x;
      best_solution = sol;
      res.summary = sum;
    }
  }
  Require(best.size() != 0, "chain fit: no chain with these parameters oscillates in every mode");
  res.masses_kg = best.segment(0, n).array().exp();
  res.springs_n_per_m = best.segment(n, n).array().exp();
  res.dampers_ns_per_m = best.segment(2 * n, n).array().exp();
  const Eigen::VectorXd& r = best_solution.residuals;
  res.chi2 = r.head(rows_data).squaredNorm();
  res.dof = static_cast<int>(rows_data - 3 * n);
  if (res.dof > 0 && res.chi2 > res.dof) res.covariance_scale = res.chi2 / res.dof;
  if (res.covariance_scale > options.max_covariance_scale && no_covariance.empty()) {
    // Widening by a factor of more than a few would make an interval of a misfit: refused.
    char text[240];
    std::snprintf(text, sizeof text,
                  "the chain does not explain the modal data (chi-square %.3g with %d degrees of "
                  "freedom, %.3g times its expectation)",
                  res.chi2, res.dof, res.covariance_scale);
    no_covariance = text;
    res.warnings.push_back(std::string("chain fit: ") + text +
                           ": no intervals (a record that cuts the ring-down short, friction, or "
                           "a rig that is not this chain)");
  } else if (res.dof > 0 && res.chi2 > ChiSquare95(res.dof) && no_covariance.empty()) {
    char text[240];
    std::snprintf(text, sizeof text,
                  "chain fit: the chain explains the modal data worse than their intervals allow "
                  "(chi-square %.3g with %d degrees of freedom, 95 %% point %.3g); the intervals "
                  "are widened by %.3g",
                  res.chi2, res.dof, ChiSquare95(res.dof), std::sqrt(res.covariance_scale));
    res.warnings.emplace_back(text);
  }
  // (J^T J)^-1 by the SVD: a direction the data and the prior leave open has no variance.
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(best_solution.jacobian, Eigen::ComputeThinV);
  const Eigen::VectorXd sv = svd.singularValues();
  Eigen::VectorXd inv2 = Eigen::VectorXd::Zero(sv.size());
  std::vector<Eigen::Index> open;
  for (Eigen::Index i = 0; i < sv.size(); ++i) {
    if (sv[i] > 1e-10 * sv[0]) {
      inv2[i] = 1.0 / (sv[i] * sv[i]);
    } else {
      open.push_back(i);
    }
  }
  const Eigen::MatrixXd cov = svd.matrixV() * inv2.asDiagonal() * svd.matrixV().transpose();
  const Eigen::VectorXd values = best.array().exp();
  if (res.prior_used) res.prior_variance_ratio.resize(3 * n);
  for (Eigen::Index i = 0; i < 3 * n; ++i) {
    bool determined = true;
    for (const Eigen::Index o : open)
      if (std::abs(svd.matrixV()(i, o)) > 1e-6) determined = false;
    Uncertainty u;
    if (!no_covariance.empty()) {
      u = Uncertainty::Missing(no_covariance);
    } else if (i >= 2 * n && !zeta_withheld.empty()) {
      u = Uncertainty::Missing(zeta_withheld);
    } else if (!determined) {
      u = Uncertainty::Missing("the test does not determine it");
    } else {
      u.variance = values[i] * values[i] * cov(i, i) * res.covariance_scale;
      u.dof = res.covariance_scale > 1.0 ? static_cast<double>(res.dof)
                                         : std::numeric_limits<double>::infinity();
      u.basis = res.prior_used ? "chain fit to the modal covariance, nominal prior"
                               : "chain fit to the modal covariance";
    }
    ParameterSource source = ParameterSource::kTest;
    if (res.prior_used) {
      const double ratio = determined ? cov(i, i) / (prior_sd[i] * prior_sd[i]) : 1.0;
      res.prior_variance_ratio[i] = ratio;
      source = ratio < options.prior_ratio_determined   ? ParameterSource::kTest
               : ratio > options.prior_ratio_from_prior ? ParameterSource::kPrior
                                                        : ParameterSource::kTestAndPrior;
    }
    res.source.push_back(source);
    (i < n ? res.m_u : i < 2 * n ? res.k_u : res.c_u).push_back(u);
  }
  if (!res.summary.Converged()) {
    res.warnings.push_back("chain fit: did not converge (" + res.summary.message + ")");
  }
  return res;
}

}  // namespace vibid::ident
