#include "vibid/ident/modal_model.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>

#include "band.hpp"
#include "vibid/common/error.hpp"

namespace vibid::ident {

std::array<double, 2> ModalInterval95(double value, double sd) {
  if (!(std::isfinite(sd) && sd > 0.0 && std::isfinite(value))) {
    return {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
  }
  return {value - kZ95 * sd, value + kZ95 * sd};
}

void ModalModelOptions::Validate() const {
  RequireBand(freq_min_hz, freq_max_hz, "modal model");
  Require(max_iterations >= 0 && max_iterations <= 1000, "modal model: iterations must be 0..1000");
  Require(max_lines >= 64, "modal model: max_lines must be >= 64");
}

namespace {

using cd = std::complex<double>;

struct Problem {
  Eigen::VectorXd w;       // lines, rad/s
  Eigen::MatrixXcd h;      // lines x responses, accelerance
  Eigen::MatrixXd weight;  // lines x responses, 1 / standard deviation (0: line not used)
  Eigen::Index modes = 0;
  double pretrigger_s = 0.0;

  Eigen::Index lines() const { return w.size(); }
  Eigen::Index responses() const { return h.cols(); }
  // Residue families: the hit's response, and with a pretrigger the ringing term (header).
  Eigen::Index families() const { return pretrigger_s > 0.0 ? 2 : 1; }
  Eigen::Index per_response() const { return 2 * modes * families() + 2; }
  Eigen::Index parameters() const { return 2 * modes + responses() * per_response(); }

  static cd Pole(double omega, double zeta) {
    return {-zeta * omega, omega * std::sqrt(std::max(0.0, 1.0 - zeta * zeta))};
  }

  // Weighted residuals (Re, Im per line, responses stacked) and, when `jac` is given, their
  // Jacobian in theta = [omega_i, zeta_i ..., per response a_i, b_i ..., c, d].
  void Evaluate(const Eigen::VectorXd& theta, Eigen::VectorXd& r, Eigen::MatrixXd* jac) const {
    const Eigen::Index L = lines();
    r.resize(2 * L * responses());
    if (jac) jac->setZero(2 * L * responses(), parameters());
    std::vector<cd> lam(static_cast<std::size_t>(modes)), dl_dw(lam.size()), dl_dz(lam.size());
    for (Eigen::Index i = 0; i < modes; ++i) {
      const double om = theta[2 * i];
      const double ze = theta[2 * i + 1];
      const auto u = static_cast<std::size_t>(i);
      lam[u] = Pole(om, ze);
      dl_dw[u] = lam[u] / om;
      dl_dz[u] = cd(-om, -om * ze / std::sqrt(std::max(1e-300, 1.0 - ze * ze)));
    }
    for (Eigen::Index o = 0; o < responses(); ++o) {
      const Eigen::Index base = 2 * modes + o * per_response();
      const Eigen::Index tail = base + 2 * modes * families();
      const double c = theta[tail];
      const double d = theta[tail + 1];
      for (Eigen::Index k = 0; k < L; ++k) {
        const double wk = weight(k, o);
        const cd jw(0.0, w[k]);
        cd m = c - w[k] * w[k] * d;
        const Eigen::Index row = 2 * (o * L + k);
        const cd shift = std::polar(1.0, w[k] * pretrigger_s);
        for (Eigen::Index i = 0; i < modes; ++i) {
          const auto u = static_cast<std::size_t>(i);
          const cd p = 1.0 / (jw - lam[u]);
          const cd q = 1.0 / (jw - std::conj(lam[u]));
          cd dw = 0.0;
          cd dz = 0.0;
          for (Eigen::Index f = 0; f < families(); ++f) {
            const cd e = f == 0 ? cd(1.0) : shift;
            const Eigen::Index at = base + 2 * modes * f + 2 * i;
            const cd res(theta[at], theta[at + 1]);
            m += e * (res * p + std::conj(res) * q);
            if (!jac) continue;
            const cd da = e * (p + q);
            const cd db = e * cd(0.0, 1.0) * (p - q);
            dw += e * (res * p * p * dl_dw[u] + std::conj(res) * q * q * std::conj(dl_dw[u]));
            dz += e * (res * p * p * dl_dz[u] + std::conj(res) * q * q * std::conj(dl_dz[u]));
            (*jac)(row, at) = wk * da.real();
            (*jac)(row + 1, at) = wk * da.imag();
            (*jac)(row, at + 1) = wk * db.real();
            (*jac)(row + 1, at + 1) = wk * db.imag();
          }
          if (!jac) continue;
          (*jac)(row, 2 * i) = wk * dw.real();
          (*jac)(row + 1, 2 * i) = wk * dw.imag();
          (*jac)(row, 2 * i + 1) = wk * dz.real();
          (*jac)(row + 1, 2 * i + 1) = wk * dz.imag();
        }
        if (jac) {
          (*jac)(row, tail) = wk;
          (*jac)(row, tail + 1) = -wk * w[k] * w[k];
        }
        const cd e = wk * (m - h(k, o));
        r[row] = e.real();
        r[row + 1] = e.imag();
      }
    }
  }

  // Residues and residual terms by linear least squares with the poles of theta held.
  void SolveLinear(Eigen::VectorXd& theta) const {
    Eigen::VectorXd r;
    Eigen::MatrixXd jac;
    Evaluate(theta, r, &jac);
    const Eigen::Index L = lines();
    for (Eigen::Index o = 0; o < responses(); ++o) {
      const Eigen::Index base = 2 * modes + o * per_response();
      const Eigen::MatrixXd a = jac.block(2 * o * L, base, 2 * L, per_response());
      // r = a x_current - y: the new x solves a x = y = a x_current - r.
      const Eigen::VectorXd y =
          a * theta.segment(base, per_response()) - r.segment(2 * o * L, 2 * L);
      const Eigen::VectorXd scale = a.colwise().norm().transpose().cwiseMax(1e-300).cwiseInverse();
      const Eigen::VectorXd x = (a * scale.asDiagonal()).colPivHouseholderQr().solve(y);
      theta.segment(base, per_response()) = scale.cwiseProduct(x);
    }
  }
};

}  // namespace

double ModalModelFit::ShapeRatio(Eigen::Index mode, Eigen::Index j, Eigen::Index p) const {
  const cd rj = residues(mode, j);
  const cd rp = residues(mode, p);
  return std::norm(rp) > 0.0 ? std::real(rj * std::conj(rp)) / std::norm(rp)
                             : std::numeric_limits<double>::quiet_NaN();
}

double ModalModelFit::ShapeRatioSd(Eigen::Index mode, Eigen::Index j, Eigen::Index p) const {
  if (j == p) return 0.0;
  const Eigen::Index modes = lambda.size();
  const Eigen::Index per = per_response;
  const cd rj = residues(mode, j);
  const cd rp = residues(mode, p);
  const double n2 = std::norm(rp);
  if (!(n2 > 0.0) || covariance.rows() == 0) return std::numeric_limits<double>::quiet_NaN();
  const double ratio = std::real(rj * std::conj(rp)) / n2;
  // Gradient in Re, Im of the resonance residues, then through R + S exp(j omega_d t_p) to the
  // parameters (the phase's own dependence on the pole is of second order).
  const double gr[2][2] = {
      {rp.real() / n2, rp.imag() / n2},
      {(rj.real() - 2.0 * rp.real() * ratio) / n2, (rj.imag() - 2.0 * rp.imag() * ratio) / n2}};
  const Eigen::Index at[2] = {2 * modes + j * per + 2 * mode, 2 * modes + p * per + 2 * mode};
  const cd e = std::polar(1.0, lambda[mode].imag() * pretrigger_s);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(covariance.rows());
  for (int k = 0; k < 2; ++k) {
    g[at[k]] = gr[k][0];
    g[at[k] + 1] = gr[k][1];
    if (per > 2 * modes + 2) {
      const Eigen::Index s_at = at[k] + 2 * modes;
      g[s_at] = gr[k][0] * e.real() + gr[k][1] * e.imag();
      g[s_at + 1] = -gr[k][0] * e.imag() + gr[k][1] * e.real();
    }
  }
  return std::sqrt(Variance(g));
}

double ModalModelFit::Variance(const Eigen::VectorXd& gradient) const {
  constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
  if (covariance.rows() != gradient.size() || covariance.rows() == 0) return kNone;
  const double v = gradient.dot(covariance * gradient);
  if (undetermined.cols() > 0) {
    // Even at the least variance an undetermined direction can have, it outweighs what the
    // determined ones give: the data do not fix this quantity.
    const double least =
        (undetermined.transpose() * gradient).squaredNorm() * undetermined_variance;
    if (!(least <= v)) return kNone;
  }
  return std::isfinite(v) && v > 0.0 ? v : kNone;
}

namespace {

// Lines of the fit: the band around the start poles (or the options' band); on a long FRF only
// the lines near a pole.
std::vector<Eigen::Index> FitLines(const Frf& acc, const std::vector<std::complex<double>>& start,
                                   const ModalModelOptions& options) {
  double fmin = std::numeric_limits<double>::infinity();
  double fmax = 0.0;
  for (const cd& l : start) {
    Require(std::isfinite(l.real()) && std::isfinite(l.imag()) && l.real() < 0.0 && l.imag() > 0.0,
            "modal model fit: start poles must be stable and oscillating");
    fmin = std::min(fmin, std::abs(l) / (2.0 * std::numbers::pi));
    fmax = std::max(fmax, std::abs(l) / (2.0 * std::numbers::pi));
  }
  const double lo = options.freq_min_hz > 0.0 ? options.freq_min_hz : 0.6 * fmin;
  const double hi = options.freq_max_hz > 0.0 ? options.freq_max_hz : 1.4 * fmax;
  std::vector<Eigen::Index> rows;
  for (Eigen::Index k = 0; k < acc.freq_hz.size(); ++k) {
    const double f = acc.freq_hz[k];
    if (f > 0.0 && f >= lo && f <= hi) rows.push_back(k);
  }
  if (static_cast<int>(rows.size()) > options.max_lines && acc.freq_hz.size() >= 2) {
    // A long FRF (a 50 kHz single-hit record): the poles are decided near their resonances, so
    // only the lines within 10 half-power bandwidths (at least 32 lines) of a pole are fitted,
    // which keeps the cost linear in the number of modes.
    const double df = acc.freq_hz[1] - acc.freq_hz[0];
    std::vector<Eigen::Index> near;
    for (const Eigen::Index k : rows) {
      const double f = acc.freq_hz[k];
      for (const cd& l : start) {
        const double fp = std::abs(l) / (2.0 * std::numbers::pi);
        const double half =
            std::max(10.0 * 2.0 * (-l.real()) / (2.0 * std::numbers::pi), 32.0 * df);
        if (std::abs(f - fp) <= half) {
          near.push_back(k);
          break;
        }
      }
    }
    rows = std::move(near);
  }
  return rows;
}

// Fills the problem's frequencies, FRF and first weights (1 / peak, 0 where the coherence is 0).
void LoadLines(const Frf& acc, const std::vector<Eigen::Index>& rows, Problem& prob) {
  const auto L = static_cast<Eigen::Index>(rows.size());
  const Eigen::Index R = acc.h.cols();
  prob.w.resize(L);
  prob.h.resize(L, R);
  prob.weight.resize(L, R);
  for (Eigen::Index o = 0; o < R; ++o) {
    double top = 0.0;
    for (Eigen::Index k = 0; k < L; ++k) {
      const Eigen::Index src = rows[static_cast<std::size_t>(k)];
      prob.w[k] = 2.0 * std::numbers::pi * acc.freq_hz[src];
      prob.h(k, o) = acc.h(src, o);
      top = std::max(top, std::abs(acc.h(src, o)));
    }
    Require(top > 0.0,
            "modal model fit: response " + std::to_string(o + 1) + " is zero in the band");
    // Lines where the force had no energy (coherence 0) carry no FRF. The noise level is set from
    // the residuals after the first fit.
    for (Eigen::Index k = 0; k < L; ++k) {
      prob.weight(k, o) =
          acc.coherence(rows[static_cast<std::size_t>(k)], o) > 0.0 ? 1.0 / top : 0.0;
    }
  }
}

Eigen::VectorXd StartParameters(const std::vector<std::complex<double>>& start,
                                const Problem& prob) {
  Eigen::VectorXd theta = Eigen::VectorXd::Zero(prob.parameters());
  for (Eigen::Index i = 0; i < prob.modes; ++i) {
    const cd l = start[static_cast<std::size_t>(i)];
    theta[2 * i] = std::abs(l);
    theta[2 * i + 1] = -l.real() / std::abs(l);
  }
  return theta;
}

double UsedLines(const Problem& prob, Eigen::Index o) {
  return static_cast<double>((prob.weight.col(o).array() > 0.0).count());
}

void Refine(Problem& prob, const ModalModelOptions& options, Eigen::VectorXd& th,
            numerics::SolverSummary& summary) {
  if (options.max_iterations == 0) {
    Eigen::VectorXd r;
    prob.Evaluate(th, r, nullptr);
    summary = {};
    summary.termination = numerics::TerminationType::kFunctionTolerance;
    summary.initial_cost = summary.final_cost = 0.5 * r.squaredNorm();
    summary.message = "residues by linear least squares with the poles held";
    return;
  }
  // Poles stay physical: omega > 0 and 0 < zeta < 1; a step outside is rejected.
  const numerics::ResidualFunction residuals = [&prob](const Eigen::VectorXd& t, Eigen::VectorXd& r,
                                                       Eigen::MatrixXd* jac) {
    for (Eigen::Index i = 0; i < prob.modes; ++i) {
      if (!(t[2 * i] > 0.0 && t[2 * i + 1] > 0.0 && t[2 * i + 1] < 1.0)) return false;
    }
    prob.Evaluate(t, r, jac);
    return true;
  };
  const numerics::SolverOptions solver{.max_iterations = options.max_iterations,
                                       .function_tolerance = 1e-10};
  summary = numerics::LevenbergMarquardt(residuals, th, solver);
  summary.message = "poles and residues refined (weighted least squares): " + summary.message;
}

// Each response's weight scaled by its noise level, estimated from the residuals at `theta`.
void WeightByNoiseLevel(const Eigen::VectorXd& theta, Problem& prob) {
  const Eigen::Index L = prob.lines();
  const Eigen::Index R = prob.responses();
  Eigen::VectorXd r;
  prob.Evaluate(theta, r, nullptr);
  for (Eigen::Index o = 0; o < R; ++o) {
    const double dof =
        std::max(1.0, 2.0 * UsedLines(prob, o) - static_cast<double>(prob.per_response()) -
                          2.0 * static_cast<double>(prob.modes) / static_cast<double>(R));
    const double s2 =
        r.segment(2 * o * L, 2 * L).squaredNorm() / dof;  // in units of the old weights
    if (s2 > 0.0) prob.weight.col(o) /= std::sqrt(s2);
  }
}

// Directions of the column-scaled information matrix with an eigenvalue below this fraction of
// the largest are not determined by the band's lines: double precision cannot resolve them (a
// singular value of the scaled Jacobian below 1e-6 of the largest).
constexpr double kUndeterminedEigenvalue = 1e-12;

// Covariance on the determined directions (pseudo-inverse of the information matrix), and the
// undetermined directions themselves: a quantity that moves along one of them has no interval.
// Why not the plain inverse: where the lines cannot tell two parameters apart (the ringing terms
// of a short record against the hit's own residues and the constant term) the inverse of a
// numerically singular matrix is noise, with negative variances that would print as +- 0.
void EstimateCovariance(const Problem& prob, const Eigen::VectorXd& theta, ModalModelFit& out) {
  Eigen::VectorXd r;
  Eigen::MatrixXd jac;
  prob.Evaluate(theta, r, &jac);
  double obs = 0.0;
  for (Eigen::Index o = 0; o < prob.responses(); ++o) obs += 2.0 * UsedLines(prob, o);
  const double dof = std::max(1.0, obs - static_cast<double>(prob.parameters()));
  out.reduced_chi2 = r.squaredNorm() / dof;
  const Eigen::VectorXd scale = jac.colwise().norm().transpose().cwiseMax(1e-300).cwiseInverse();
  const Eigen::MatrixXd js = jac * scale.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(js.transpose() * js);
  const Eigen::VectorXd ev = es.eigenvalues();
  const Eigen::MatrixXd& v = es.eigenvectors();
  const double top = ev.size() > 0 ? ev[ev.size() - 1] : 0.0;
  const double floor = kUndeterminedEigenvalue * top;
  Eigen::VectorXd inv = Eigen::VectorXd::Zero(ev.size());
  std::vector<Eigen::Index> undetermined;
  for (Eigen::Index k = 0; k < ev.size(); ++k) {
    if (ev[k] > floor && top > 0.0) {
      inv[k] = 1.0 / ev[k];
    } else {
      undetermined.push_back(k);
    }
  }
  out.min_eigenvalue_ratio = top > 0.0 ? std::max(0.0, ev[0]) / top : 0.0;
  // The noise level is estimated, so the covariance takes the misfit per degree of freedom as it
  // is (Gauss-Newton covariance with an unknown variance).
  const Eigen::MatrixXd sv = scale.asDiagonal() * v;
  out.covariance = sv * inv.asDiagonal() * sv.transpose() * out.reduced_chi2;
  out.undetermined.resize(prob.parameters(), static_cast<Eigen::Index>(undetermined.size()));
  for (std::size_t k = 0; k < undetermined.size(); ++k)
    out.undetermined.col(static_cast<Eigen::Index>(k)) = sv.col(undetermined[k]);
  // The least variance an undetermined direction can have: its eigenvalue at the floor.
  out.undetermined_variance =
      top > 0.0 ? out.reduced_chi2 / floor : std::numeric_limits<double>::infinity();
}

void StoreResidues(const Problem& prob, const Eigen::VectorXd& theta, Eigen::Index i,
                   ModalModelFit& out) {
  const Eigen::Index M = prob.modes;
  const cd lam = out.lambda[i];
  for (Eigen::Index o = 0; o < out.residues.cols(); ++o) {
    const Eigen::Index base = 2 * M + o * prob.per_response();
    out.residues(i, o) = cd(theta[base + 2 * i], theta[base + 2 * i + 1]);
    if (prob.families() == 2) {
      // Around the peak the ringing term adds to the hit's own with the phase exp(j omega_d t_p);
      // the two are hard to tell apart there (large, opposite errors) but their sum is sharp.
      out.residues(i, o) += cd(theta[base + 2 * M + 2 * i], theta[base + 2 * M + 2 * i + 1]) *
                            std::polar(1.0, lam.imag() * prob.pretrigger_s);
    }
  }
}

// The window moved the real part by -1/tau; omega and zeta of the structure from the moved-back
// pole, with the gradient through it.
void StoreStructurePole(double om, double ze, double tau, Eigen::Index i, ModalModelFit& out) {
  const cd lam = out.lambda[i];
  const cd lt = tau > 0.0 ? lam + 1.0 / tau : lam;
  const double wt = std::abs(lt);
  out.omega_rad_s[i] = wt;
  out.zeta[i] = -lt.real() / wt;
  const cd dl_dw = lam / om;
  const cd dl_dz(-om, -om * ze / std::sqrt(std::max(1e-300, 1.0 - ze * ze)));
  Eigen::Matrix2d g;  // rows: omega_t, zeta_t; columns: omega, zeta
  for (int c = 0; c < 2; ++c) {
    const cd dl = c == 0 ? dl_dw : dl_dz;
    const double dwt = std::real(std::conj(lt) * dl) / wt;
    g(0, c) = dwt;
    g(1, c) = -dl.real() / wt + lt.real() * dwt / (wt * wt);
  }
  for (int row = 0; row < 2; ++row) {
    Eigen::VectorXd full = Eigen::VectorXd::Zero(out.covariance.rows());
    full.segment<2>(2 * i) = g.row(row).transpose();
    (row == 0 ? out.omega_sd_rad_s : out.zeta_sd)[i] = std::sqrt(out.Variance(full));
  }
}

void StoreModes(const Problem& prob, const Eigen::VectorXd& theta, double tau, ModalModelFit& out) {
  const Eigen::Index M = prob.modes;
  const Eigen::Index R = prob.responses();
  out.lambda.resize(M);
  out.per_response = prob.per_response();
  out.pretrigger_s = prob.pretrigger_s;
  out.residues.resize(M, R);
  out.omega_rad_s.resize(M);
  out.zeta.resize(M);
  out.omega_sd_rad_s.resize(M);
  out.zeta_sd.resize(M);
  for (Eigen::Index i = 0; i < M; ++i) {
    const double om = theta[2 * i];
    const double ze = theta[2 * i + 1];
    out.lambda[i] = Problem::Pole(om, ze);
    StoreResidues(prob, theta, i, out);
    StoreStructurePole(om, ze, tau, i, out);
  }
}

}  // namespace

namespace {

// The fit of one model (with or without the ringing terms) from the start poles.
ModalModelFit FitProblem(Problem prob, const std::vector<std::complex<double>>& start,
                         const ModalModelOptions& options, double exp_window_tau_s) {
  Require(prob.lines() > prob.per_response() + prob.modes,
          "modal model fit: too few frequency lines in the band");
  Eigen::VectorXd theta = StartParameters(start, prob);
  prob.SolveLinear(theta);
  ModalModelFit out;
  out.lines = static_cast<int>(prob.lines());
  out.ringing_terms = prob.families() == 2;
  Refine(prob, options, theta, out.summary);
  // Once more with each response weighted by its noise level.
  WeightByNoiseLevel(theta, prob);
  Refine(prob, options, theta, out.summary);
  EstimateCovariance(prob, theta, out);
  StoreModes(prob, theta, exp_window_tau_s, out);
  return out;
}

}  // namespace

ModalModelFit FitModalModel(const Frf& receptance, const std::vector<std::complex<double>>& start,
                            const ModalModelOptions& options) {
  options.Validate();
  Require(receptance.quantity == Quantity::kDisplacement, "modal model fit needs a receptance FRF");
  Require(!start.empty(), "modal model fit needs at least one pole");
  const Frf acc = ConvertFrf(receptance, Quantity::kAcceleration);
  const std::vector<Eigen::Index> rows = FitLines(acc, start, options);
  Problem prob;
  prob.modes = static_cast<Eigen::Index>(start.size());
  prob.pretrigger_s = receptance.pretrigger_s;
  const auto L = static_cast<Eigen::Index>(rows.size());
  Require(L > prob.per_response() + prob.modes,
          "modal model fit: too few frequency lines in the band");
  LoadLines(acc, rows, prob);

  ModalModelFit out = FitProblem(prob, start, options, acc.exp_window_tau_s);
  out.freq_min_hz = acc.freq_hz[rows.front()];
  out.freq_max_hz = acc.freq_hz[rows.back()];
  if (!out.ringing_terms || out.undetermined.cols() == 0) return out;
  Problem plain = prob;
  plain.pretrigger_s = 0.0;
  ModalModelFit alt;
  try {
    alt = FitProblem(plain, start, options, acc.exp_window_tau_s);
  } catch (const InputError&) {
    return out;
  }
  bool near = alt.summary.Converged() && alt.undetermined.cols() == 0;
  for (Eigen::Index i = 0; near && i < alt.omega_rad_s.size(); ++i) {
    near = std::abs(alt.omega_rad_s[i] - out.omega_rad_s[i]) <= 0.01 * out.omega_rad_s[i] &&
           std::abs(alt.zeta[i] - out.zeta[i]) <= 0.5 * out.zeta[i];
  }
  if (!near) return out;
  alt.freq_min_hz = out.freq_min_hz;
  alt.freq_max_hz = out.freq_max_hz;
  char line[240];
  std::snprintf(line, sizeof line,
                "the %d lines of %.4g..%.4g Hz do not tell the ringing terms of the %.4g s "
                "pretrigger from the hit's own residues: modal model without them, no intervals "
                "(hits further apart give both)",
                out.lines, out.freq_min_hz, out.freq_max_hz, prob.pretrigger_s);
  alt.note = line;
  alt.ringing_terms_dropped = true;
  return alt;
}

}  // namespace vibid::ident
