#include "vibid/ident/updates.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <numbers>
#include <sstream>

#include <Eigen/Cholesky>
#include <Eigen/QR>

#include "vibid/common/error.hpp"

namespace vibid::ident {

void MassUpdateOptions::Validate() const {
  Require(k_n_per_m >= 0.0 && std::isfinite(k_n_per_m),
          "mass update: stiffness must be >= 0 (0: fit it)");
  Require(nominal_kg >= 0.0 && std::isfinite(nominal_kg), "mass update: nominal mass must be >= 0");
  Require(band_fraction > 0.0 && band_fraction < 1.0,
          "mass update: band fraction must be in (0, 1)");
  peaks.Validate();
  solver.Validate();
}

namespace {

// The largest resonance of column `col`, and the picker's warnings about it alone (other peaks,
// such as noise at low frequency, are not reported).
Peak LargestResonance(const Frf& receptance, Eigen::Index col, const MassUpdateOptions& options,
                      std::vector<std::string>& warnings) {
  // The grid's resolution of the half-power band only matters when c is held at its value; the
  // fit refines c otherwise, so the picker need not warn about it.
  PeakOptions peak_options = options.peaks;
  if (options.fit_damping) peak_options.min_lines_in_band = 0.0;
  const PeakResult picked =
      PickPeaks(receptance.freq_hz, PickingMagnitude(receptance, static_cast<int>(col)),
                peak_options, receptance.exp_window_tau_s);
  Require(!picked.peaks.empty(), "mass update: no resonance found in the FRF");
  const Peak peak =
      *std::max_element(picked.peaks.begin(), picked.peaks.end(),
                        [](const Peak& a, const Peak& b) { return a.magnitude < b.magnitude; });
  for (const std::string& w : picked.warnings) {
    std::ostringstream at;
    at << "peak at " << peak.freq_hz << " Hz";
    if (w.rfind(at.str(), 0) == 0) warnings.push_back(w);
  }
  return peak;
}

// The lines around the resonance that the single-DOF model is fitted to.
struct ResonanceLines {
  Eigen::VectorXd omega;
  Eigen::VectorXd log_mag;
  Eigen::VectorXd weight;
};

ResonanceLines LinesAroundResonance(const Frf& receptance, Eigen::Index col,
                                    const Eigen::VectorXd& mag, const Peak& peak,
                                    const MassUpdateOptions& options) {
  std::vector<Eigen::Index> rows;
  for (Eigen::Index i = 0; i < receptance.freq_hz.size(); ++i) {
    const double w = 2.0 * std::numbers::pi * receptance.freq_hz[i];
    if (w > 0.0 && std::abs(w - peak.omega_rad_s) <= options.band_fraction * peak.omega_rad_s &&
        mag[i] > 0.0) {
      rows.push_back(i);
    }
  }
  Require(rows.size() >= 5,
          "mass update: fewer than 5 frequency lines in the band around the resonance");
  const auto nrows = static_cast<Eigen::Index>(rows.size());
  ResonanceLines lines;
  lines.omega.resize(nrows);
  lines.log_mag.resize(nrows);
  lines.weight.resize(nrows);
  for (Eigen::Index r = 0; r < nrows; ++r) {
    const Eigen::Index i = rows[static_cast<std::size_t>(r)];
    lines.omega[r] = 2.0 * std::numbers::pi * receptance.freq_hz[i];
    lines.log_mag[r] = std::log(mag[i]);
    lines.weight[r] =
        options.coherence_weighting ? std::sqrt(std::max(receptance.coherence(i, col), 0.0)) : 1.0;
  }
  return lines;
}

// Single-DOF log-magnitude misfit. Parameters are log-scale factors on the start:
// q = [m, k (if fitted), zeta (if fitted)].
//
// The model is what an impact test's H1 of this single DOF is, not the bare receptance: the
// responses measured quantity r (0 displacement, 2 acceleration) has the impulse response
// s^r H(s) = d_r2 / m + sum_i rho_i / (s - p_i), rho_i = p_i^r / (m (p_i - p_j)), p_i the roots of
// m s^2 + c s + k. The exponential window exp(-a t) from the trigger moves every pole to
// q_i = p_i - a (the direct term, the hit itself, stays). The record's end, T - t_p after the hit
// (t_p the pretrigger), cuts each decay: on the record's lines (exp(-j w T) = 1) a term becomes
// rho_i (1 - exp(q_i (T - t_p)) exp(j w t_p)) / (j w - q_i). The FRF is then divided by (j w)^r to
// give the receptance it was converted to. Leaving the cut out put |H| up to 0.1 exp(-zeta w T)
// off (a window ending at 0.1): m and k 0.2 % low or high as the record length fell, on records
// of 3.5 s of a 7 Hz, 3 % damped mass; and H(s + a) for s^-2 H_a(s + a) put |H| (a / w)^2 high.
struct SingleDofFit {
  const ResonanceLines* lines = nullptr;
  double m0 = 0.0;
  double k0 = 0.0;
  double zeta0 = 0.0;
  double a_w = 0.0;           // 1 / tau of the exponential window, 0 without one
  double record_s = 0.0;      // impact records: each hit's record length, 0 when not cut
  double pretrigger_s = 0.0;  // impact records: the hit's time in its record
  int measured_order = 0;     // the responses' quantity: 0 displacement, 1 velocity, 2 acceleration
  Eigen::Index k_index = -1;
  Eigen::Index zeta_index = -1;

  Eigen::Index parameters() const { return 1 + (k_index >= 0 ? 1 : 0) + (zeta_index >= 0 ? 1 : 0); }

  void Unpack(const Eigen::VectorXd& q, double& m, double& k, double& zeta) const {
    m = m0 * std::exp(q[0]);
    k = k_index >= 0 ? k0 * std::exp(q[k_index]) : k0;
    zeta = zeta_index >= 0 ? zeta0 * std::exp(q[zeta_index]) : zeta0;
  }

  void Residuals(double m, double k, double c, Eigen::VectorXd& r) const {
    using cd = std::complex<double>;
    const Eigen::VectorXd& omega = lines->omega;
    const Eigen::Index nrows = omega.size();
    r.resize(nrows);
    const cd root = std::sqrt(cd(c * c - 4.0 * m * k, 0.0));
    const std::array<cd, 2> p{(-c + root) / (2.0 * m), (-c - root) / (2.0 * m)};
    if (std::abs(p[0] - p[1]) <= 1e-9 * std::abs(p[0])) {
      // Critical damping: the partial fractions degenerate; no resonance to fit there.
      r.setConstant(1e3);
      return;
    }
    std::array<cd, 2> rho, pole, cut;
    for (std::size_t i = 0; i < 2; ++i) {
      rho[i] = std::pow(p[i], measured_order) / (m * (p[i] - p[1 - i]));
      pole[i] = p[i] - a_w;
      cut[i] = record_s > 0.0 ? std::exp(pole[i] * (record_s - pretrigger_s)) : cd(0.0, 0.0);
    }
    const double direct = measured_order == 2 ? 1.0 / m : 0.0;
    for (Eigen::Index l = 0; l < nrows; ++l) {
      const cd jw(0.0, omega[l]);
      const cd shift = std::exp(jw * pretrigger_s);
      cd h = direct;
      for (std::size_t i = 0; i < 2; ++i) h += rho[i] * (1.0 - cut[i] * shift) / (jw - pole[i]);
      h /= std::pow(jw, measured_order);
      r[l] = lines->weight[l] * (std::log(std::abs(h)) - lines->log_mag[l]);
    }
  }
};

// The relative level error of a 1-DOF hammer test per unit of the amplitude a hit leaves at its
// record's end, which the next hit's record holds at its start (where no exponential window takes
// it off). Measured with an independent simulator (benchmarks/coverage/chain_coverage.py, 1-DOF
// cases: 1.53 kg, 2760 N/m, zeta 2.7 %, hits 3.5-6.5 s apart, 1.8 % left): at 0.03 % noise m
// scattered by 0.11-0.13 % over the seeds, with and without a window, against intervals of
// +- 0.096 % (5 and 4 of 8 inside); 0.1 per unit left holds it.
constexpr double kRingingLevelPerLeft = 0.1;

// The fit's covariance in its log-scale parameters q, carried to m, k and c = 2 zeta sqrt(k m):
// dm = m dq_m, dk = k dq_k, dc = c (dq_m / 2 + dq_k / 2 + dq_zeta).
void FitUncertainties(const numerics::ResidualOnlyFunction& f, const Eigen::VectorXd& q,
                      const SingleDofFit& fit, double level_rel_var, double ringing_rel_var,
                      MassUpdateResult& res) {
  Eigen::VectorXd r;
  Eigen::MatrixXd jac;
  numerics::NumericDiff(f)(q, r, &jac);
  const auto nq = static_cast<double>(q.size());
  const double dof = static_cast<double>(r.size()) - nq;
  const std::string basis = "fit covariance (" + std::to_string(r.size()) + " lines" +
                            (level_rel_var > 0.0 ? ", force noise" : "") +
                            (ringing_rel_var > 0.0 ? ", the previous hit's ringing" : "") + ")";
  if (!(dof >= 1.0)) {
    res.mass_u = res.k_u = res.c_u = Uncertainty::Missing("as many parameters as fitted lines");
    return;
  }
  Eigen::MatrixXd cov = numerics::CovarianceFromJacobian(jac, r);
  // Neighbouring lines are not independent when a window smooths the spectrum (an exponential
  // window convolves it with its own transform): the covariance of independent lines is then too
  // small (by 2 in standard deviation for a known k and a window ending at 0.01, 5 hits). Noise
  // of lag-one autocorrelation rho (AR(1)) inflates it by (1 + rho) / (1 - rho); rho from the
  // residuals, held to [0, 0.9].
  double lag_one = 0.0;
  for (Eigen::Index i = 1; i < r.size(); ++i) lag_one += r[i] * r[i - 1];
  const double rho = r.squaredNorm() > 0.0 ? std::clamp(lag_one / r.squaredNorm(), 0.0, 0.9) : 0.0;
  cov *= (1.0 + rho) / (1.0 - rho);
  // The FRF's level error from force noise shifts every line's log magnitude alike; the fit
  // carries a shift d of the data to its parameters as (J^T J)^-1 J^T w d (w: the lines'
  // weights), which no residual shows. The previous hit's ringing at a record's start is an error
  // of the same kind (ringing_rel_var), which more hits of the same spacing do not shrink.
  level_rel_var += ringing_rel_var;
  if (level_rel_var > 0.0) {
    const Eigen::VectorXd g =
        Eigen::MatrixXd(jac.transpose() * jac).ldlt().solve(jac.transpose() * fit.lines->weight);
    cov += level_rel_var * g * g.transpose();
  }
  const auto make = [&](const Eigen::VectorXd& g) {
    Uncertainty u;
    u.variance = g.dot(cov * g);
    u.dof = dof;
    u.basis = basis;
    if (!std::isfinite(u.variance)) u = Uncertainty::Missing("the fit does not determine it");
    return u;
  };
  Eigen::VectorXd g = Eigen::VectorXd::Zero(q.size());
  g[0] = res.mass_kg;
  res.mass_u = make(g);
  if (fit.k_index >= 0) {
    g.setZero();
    g[fit.k_index] = res.k_n_per_m;
    res.k_u = make(g);
  } else {
    res.k_u = Uncertainty::Missing("given, not fitted");
  }
  if (fit.zeta_index >= 0) {
    g.setZero();
    g[0] = 0.5 * res.c_ns_per_m;
    if (fit.k_index >= 0) g[fit.k_index] = 0.5 * res.c_ns_per_m;
    g[fit.zeta_index] = res.c_ns_per_m;
    res.c_u = make(g);
  } else {
    res.c_u = Uncertainty::Missing("damping held at its half-power value (--fixed-damping)");
  }
}

}  // namespace

MassUpdateResult UpdateMass(const Frf& receptance, std::size_t response,
                            const MassUpdateOptions& options) {
  options.Validate();
  Require(receptance.quantity == Quantity::kDisplacement, "mass update needs a receptance FRF");
  Require(response < receptance.responses(), "mass update: response column out of range");
  const auto col = static_cast<Eigen::Index>(response);
  const Eigen::VectorXd mag = receptance.h.col(col).cwiseAbs();
  MassUpdateResult res;
  const Peak peak = LargestResonance(receptance, col, options, res.warnings);
  res.omega_rad_s = peak.omega_rad_s;
  res.nominal_kg = options.nominal_kg;
  Require(peak.zeta > 0.0, "mass update: the half-power damping is not positive");

  const ResonanceLines lines = LinesAroundResonance(receptance, col, mag, peak, options);
  res.lines_fitted = static_cast<std::size_t>(lines.omega.size());
  // Start: k given (or from the peak height 1/(2 zeta k)), m = k / omega^2.
  res.stiffness_fitted = options.k_n_per_m == 0.0;
  res.damping_fitted = options.fit_damping;
  // Receptance peak height 1/(2 zeta k) gives the starting stiffness when it is not known.
  const double peak_receptance =
      std::abs(InterpolateAt(receptance.freq_hz, receptance.h.col(col), peak.freq_hz));
  SingleDofFit fit;
  fit.lines = &lines;
  fit.k0 = res.stiffness_fitted ? 1.0 / (2.0 * peak.zeta * peak_receptance) : options.k_n_per_m;
  fit.m0 = fit.k0 / (peak.omega_rad_s * peak.omega_rad_s);
  fit.zeta0 = peak.zeta;
  res.zeta_half_power = peak.zeta;
  fit.a_w = receptance.exp_window_tau_s > 0.0 ? 1.0 / receptance.exp_window_tau_s : 0.0;
  fit.record_s = receptance.record_s;
  fit.pretrigger_s = receptance.pretrigger_s;
  fit.measured_order = receptance.measured == Quantity::kAcceleration ? 2
                       : receptance.measured == Quantity::kVelocity   ? 1
                                                                      : 0;
  fit.k_index = res.stiffness_fitted ? 1 : -1;
  fit.zeta_index = options.fit_damping ? (res.stiffness_fitted ? 2 : 1) : -1;
  Eigen::VectorXd p = Eigen::VectorXd::Zero(fit.parameters());
  const numerics::ResidualOnlyFunction f = [&fit](const Eigen::VectorXd& q, Eigen::VectorXd& r) {
    double m = 0.0, k = 0.0, zeta = 0.0;
    fit.Unpack(q, m, k, zeta);
    fit.Residuals(m, k, 2.0 * zeta * std::sqrt(k * m), r);
    return true;
  };
  res.summary = numerics::LevenbergMarquardt(numerics::NumericDiff(f), p, options.solver);
  fit.Unpack(p, res.mass_kg, res.k_n_per_m, res.zeta);
  res.c_ns_per_m = 2.0 * res.zeta * std::sqrt(res.k_n_per_m * res.mass_kg);
  // The force noise's level error at the resonance (flat over the fitted band).
  double level_rel_var = 0.0;
  if (receptance.level_rel_var.size() == receptance.freq_hz.size()) {
    Eigen::Index at = 0;
    (receptance.freq_hz.array() - peak.freq_hz).abs().minCoeff(&at);
    level_rel_var = receptance.level_rel_var[at];
  }
  // The previous hit's ringing in each record, as a relative level error of
  // kRingingLevelPerLeft times the amplitude left after a record (exp(-zeta omega (T - t_p))).
  double ringing_rel_var = 0.0;
  if (receptance.record_s > receptance.pretrigger_s && res.mass_kg > 0.0 && res.k_n_per_m > 0.0) {
    const double omega = std::sqrt(res.k_n_per_m / res.mass_kg);
    const double left =
        std::exp(-res.zeta * omega * (receptance.record_s - receptance.pretrigger_s));
    ringing_rel_var = std::pow(kRingingLevelPerLeft * left, 2);
  }
  FitUncertainties(f, p, fit, level_rel_var, ringing_rel_var, res);
  if (options.nominal_kg > 0.0)
    res.change_percent = 100.0 * (res.mass_kg - options.nominal_kg) / options.nominal_kg;
  return res;
}

namespace {

// Chain contributions: spring 0 ties DOF 0 to ground, spring i ties DOF i-1 to DOF i.
Eigen::MatrixXd ChainBasis(Eigen::Index n) {
  Eigen::MatrixXd basis = Eigen::MatrixXd::Zero(n * n, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    Eigen::MatrixXd e = Eigen::MatrixXd::Zero(n, n);
    e(i, i) = 1.0;
    if (i > 0) {
      e(i - 1, i - 1) = 1.0;
      e(i - 1, i) = -1.0;
      e(i, i - 1) = -1.0;
    }
    basis.col(i) = Eigen::Map<const Eigen::VectorXd>(e.data(), n * n);
  }
  return basis;
}

Eigen::VectorXd DiagonalChain(const Eigen::MatrixXd& k) {
  const Eigen::Index n = k.rows();
  Eigen::VectorXd s(n);
  s[n - 1] = k(n - 1, n - 1);
  for (Eigen::Index i = n - 2; i >= 0; --i) s[i] = k(i, i) - s[i + 1];
  return s;
}

}  // namespace

StiffnessUpdateResult UpdateStiffness(const Eigen::Ref<const Eigen::VectorXd>& masses_kg,
                                      const Eigen::Ref<const Eigen::VectorXd>& omega_rad_s,
                                      const Eigen::Ref<const Eigen::VectorXd>& zeta,
                                      const Eigen::Ref<const Eigen::MatrixXd>& shapes) {
  const Eigen::Index n = masses_kg.size();
  Require(n >= 1, "stiffness update: no masses");
  Require((masses_kg.array() > 0.0).all() && masses_kg.allFinite(),
          "stiffness update: masses must be > 0");
  Require(shapes.rows() == n && shapes.cols() == n && omega_rad_s.size() == n && zeta.size() == n,
          "stiffness update: need as many modes (" + std::to_string(omega_rad_s.size()) +
              ") as masses (" + std::to_string(n) + ")");
  Require((omega_rad_s.array() > 0.0).all() && omega_rad_s.allFinite(),
          "stiffness update: frequencies must be > 0");
  const Eigen::MatrixXd m = masses_kg.asDiagonal();
  Eigen::MatrixXd phi = shapes;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double norm2 = phi.col(i).dot(m * phi.col(i));
    Require(norm2 > 0.0 && std::isfinite(norm2),
            "stiffness update: mode " + std::to_string(i + 1) + " has a zero shape");
    phi.col(i) /= std::sqrt(norm2);
  }
  StiffnessUpdateResult res;
  const Eigen::MatrixXd mphi = m * phi;
  res.k_matrix = mphi * omega_rad_s.array().square().matrix().asDiagonal() * mphi.transpose();
  res.c_matrix =
      mphi * (2.0 * zeta.array() * omega_rad_s.array()).matrix().asDiagonal() * mphi.transpose();
  res.springs = DiagonalChain(res.k_matrix);
  res.dampers = DiagonalChain(res.c_matrix);
  const Eigen::MatrixXd basis = ChainBasis(n);
  res.springs_lsq = basis.colPivHouseholderQr().solve(
      Eigen::Map<const Eigen::VectorXd>(res.k_matrix.data(), n * n));
  double worst = 0.0;
  for (Eigen::Index i = 1; i < n; ++i) {
    const double mismatch = 100.0 * (-res.k_matrix(i - 1, i) - res.springs[i]) / res.springs[i];
    if (std::abs(mismatch) > std::abs(worst)) worst = mismatch;
  }
  res.offdiag_mismatch_percent = worst;
  return res;
}

Eigen::MatrixXd StiffnessJacobian(const Eigen::Ref<const Eigen::VectorXd>& masses_kg,
                                  const Eigen::Ref<const Eigen::VectorXd>& omega_rad_s,
                                  const Eigen::Ref<const Eigen::VectorXd>& zeta,
                                  const Eigen::Ref<const Eigen::MatrixXd>& shapes) {
  const Eigen::Index n = masses_kg.size();
  Eigen::VectorXd x(3 * n + n * n);
  x << masses_kg, omega_rad_s, zeta,
      Eigen::Map<const Eigen::VectorXd>(Eigen::MatrixXd(shapes).data(), n * n);
  const auto outputs = [n](const Eigen::VectorXd& v) {
    const Eigen::MatrixXd s = Eigen::Map<const Eigen::MatrixXd>(v.data() + 3 * n, n, n);
    const StiffnessUpdateResult r =
        UpdateStiffness(v.head(n), v.segment(n, n), v.segment(2 * n, n), s);
    Eigen::VectorXd y(2 * n);
    y << r.springs, r.dampers;
    return y;
  };
  Eigen::MatrixXd jac(2 * n, x.size());
  for (Eigen::Index j = 0; j < x.size(); ++j) {
    // Each shape entry steps with its column's scale (a zero entry still has one); the map is a
    // rational function of x, smooth where UpdateStiffness accepts x.
    double scale = std::abs(x[j]);
    if (j >= 3 * n) scale = shapes.col((j - 3 * n) / n).cwiseAbs().maxCoeff();
    const double h = 1e-6 * std::max(scale, 1e-6);
    Eigen::VectorXd xp = x, xm = x;
    xp[j] += h;
    xm[j] -= h;
    jac.col(j) = (outputs(xp) - outputs(xm)) / (2.0 * h);
  }
  return jac;
}

StiffnessUpdateResult UpdateStiffness2(double m1_kg, double m2_kg,
                                       const std::vector<ModeEstimate>& modes) {
  Require(modes.size() == 2, "stiffness update of a 2-DOF chain needs exactly 2 modes, got " +
                                 std::to_string(modes.size()));
  Eigen::Vector2d masses(m1_kg, m2_kg);
  Eigen::Vector2d omega(modes[0].omega_rad_s, modes[1].omega_rad_s);
  Eigen::Vector2d zeta(modes[0].zeta, modes[1].zeta);
  Eigen::Matrix2d shapes;
  for (int i = 0; i < 2; ++i) {
    const ModeEstimate& m = modes[static_cast<std::size_t>(i)];
    Require(std::isfinite(m.ratio),
            "stiffness update: mode " + std::to_string(i + 1) + " has no shape ratio a1/a2");
    shapes(0, i) = m.ratio;
    shapes(1, i) = 1.0;
  }
  return UpdateStiffness(masses, omega, zeta, shapes);
}

StiffnessAverage AverageStiffness(const std::vector<StiffnessUpdateResult>& tests) {
  Require(!tests.empty(), "stiffness update: no tests to average");
  StiffnessAverage avg;
  avg.tests = tests;
  const Eigen::Index n = tests.front().springs.size();
  avg.k_matrix = Eigen::MatrixXd::Zero(n, n);
  avg.springs = Eigen::VectorXd::Zero(n);
  avg.springs_lsq = Eigen::VectorXd::Zero(n);
  avg.dampers = Eigen::VectorXd::Zero(n);
  for (const auto& t : tests) {
    Require(t.springs.size() == n, "stiffness update: tests differ in size");
    avg.k_matrix += t.k_matrix;
    avg.springs += t.springs;
    avg.springs_lsq += t.springs_lsq;
    avg.dampers += t.dampers;
    avg.offdiag_mismatch_percent += t.offdiag_mismatch_percent;
  }
  const auto count = static_cast<double>(tests.size());
  avg.k_matrix /= count;
  avg.springs /= count;
  avg.springs_lsq /= count;
  avg.dampers /= count;
  avg.offdiag_mismatch_percent /= count;
  avg.spread = Eigen::VectorXd::Zero(n);
  if (tests.size() > 1) {
    for (const auto& t : tests) avg.spread.array() += (t.springs - avg.springs).array().square();
    avg.spread = (avg.spread / (count - 1.0)).cwiseSqrt();
  }
  return avg;
}

}  // namespace vibid::ident
