#include "vibid/ident/modes.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

#include <Eigen/QR>

#include "vibid/common/error.hpp"
#include "vibid/ident/modal_model.hpp"

namespace vibid::ident {

namespace {

double Ratio(const Eigen::VectorXd& shape) {
  if (shape.size() != 2 || shape[1] == 0.0) return std::numeric_limits<double>::quiet_NaN();
  return shape[0] / shape[1];
}

// phi_j / phi_p for every response, without intervals (the methods that give none).
void SetShapeRatios(ModeEstimate& m, Eigen::Index p) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  m.shape_ratio = m.shape[p] != 0.0 ? Eigen::VectorXd(m.shape / m.shape[p])
                                    : Eigen::VectorXd::Constant(m.shape.size(), nan);
  m.shape_ratio_ci95.assign(static_cast<std::size_t>(m.shape.size()), {nan, nan});
}

}  // namespace

std::vector<ModeEstimate> ShapesFromPeaks(const Frf& receptance, std::size_t driving_point,
                                          const std::vector<Peak>& peaks) {
  Require(receptance.quantity == Quantity::kDisplacement, "mode shapes need a receptance FRF");
  Require(driving_point < receptance.responses(), "driving-point response out of range");
  std::vector<ModeEstimate> modes;
  const auto p = static_cast<Eigen::Index>(driving_point);
  for (const Peak& peak : peaks) {
    ModeEstimate m;
    m.omega_rad_s = peak.omega_rad_s;
    m.freq_hz = peak.freq_hz;
    m.zeta = peak.zeta;
    const double scale = 2.0 * peak.zeta * peak.omega_rad_s * peak.omega_rad_s;
    const std::complex<double> hpp =
        InterpolateAt(receptance.freq_hz, receptance.h.col(p), peak.freq_hz);
    const double phi_p = std::sqrt(scale * std::abs(hpp));
    m.shape.resize(receptance.h.cols());
    for (Eigen::Index j = 0; j < receptance.h.cols(); ++j) {
      if (j == p) {
        m.shape[j] = phi_p;
        continue;
      }
      const std::complex<double> hjp =
          InterpolateAt(receptance.freq_hz, receptance.h.col(j), peak.freq_hz);
      const double sign = std::real(hjp * std::conj(hpp)) >= 0.0 ? 1.0 : -1.0;
      m.shape[j] = phi_p > 0.0 ? sign * scale * std::abs(hjp) / phi_p : 0.0;
    }
    m.ratio = Ratio(m.shape);
    SetShapeRatios(m, p);
    modes.push_back(m);
  }
  return modes;
}

void CurveFitOptions::Validate() const {
  Require(freq_min_hz >= 0.0 && freq_max_hz >= 0.0, "curve fit: band limits must be >= 0");
  Require(freq_max_hz == 0.0 || freq_max_hz > freq_min_hz,
          "curve fit: band maximum must exceed the minimum");
  solver.Validate();
}

namespace {

struct FitProblem {
  Eigen::VectorXd omega;   // lines in the band, rad/s
  Eigen::MatrixXcd h;      // lines x responses
  Eigen::MatrixXd weight;  // lines x responses
  Eigen::VectorXd omega0;  // start pole frequencies (parameter scale)
  bool residual_terms = true;

  Eigen::Index modes() const { return omega0.size(); }
  Eigen::Index columns() const { return 2 * modes() + (residual_terms ? 2 : 0); }

  // p = [ln(omega_i / omega0_i), ln(zeta_i)] per mode.
  void Poles(const Eigen::VectorXd& p, Eigen::VectorXd& om, Eigen::VectorXd& ze) const {
    om.resize(modes());
    ze.resize(modes());
    for (Eigen::Index i = 0; i < modes(); ++i) {
      om[i] = omega0[i] * std::exp(p[2 * i]);
      ze[i] = std::exp(p[2 * i + 1]);
    }
  }

  // Real design matrix (rows: real and imaginary parts of every line) for real unknowns
  // [Re A_1..n, Im A_1..n, L, U].
  Eigen::MatrixXd Design(const Eigen::VectorXd& om, const Eigen::VectorXd& ze) const {
    const Eigen::Index lines = omega.size();
    Eigen::MatrixXd a = Eigen::MatrixXd::Zero(2 * lines, columns());
    for (Eigen::Index k = 0; k < lines; ++k) {
      const double w = omega[k];
      for (Eigen::Index i = 0; i < modes(); ++i) {
        const std::complex<double> b =
            1.0 / std::complex<double>(om[i] * om[i] - w * w, 2.0 * ze[i] * om[i] * w);
        // A b with A = a + j c: real part a Re b - c Im b, imaginary part a Im b + c Re b.
        a(2 * k, i) = b.real();
        a(2 * k + 1, i) = b.imag();
        a(2 * k, modes() + i) = -b.imag();
        a(2 * k + 1, modes() + i) = b.real();
      }
      if (residual_terms) {
        a(2 * k, 2 * modes()) = -1.0 / (w * w);
        a(2 * k, 2 * modes() + 1) = 1.0;
      }
    }
    return a;
  }

  // Weighted linear solve per response; returns the stacked weighted residuals.
  bool Solve(const Eigen::VectorXd& p, Eigen::VectorXd& r, Eigen::MatrixXd* coefficients) const {
    Eigen::VectorXd om;
    Eigen::VectorXd ze;
    Poles(p, om, ze);
    for (Eigen::Index i = 0; i < modes(); ++i) {
      if (!(ze[i] < 1.0) || !std::isfinite(om[i])) return false;
    }
    const Eigen::MatrixXd design = Design(om, ze);
    const Eigen::Index lines = omega.size();
    r.resize(2 * lines * h.cols());
    if (coefficients) coefficients->resize(columns(), h.cols());
    for (Eigen::Index j = 0; j < h.cols(); ++j) {
      Eigen::VectorXd rw(2 * lines);
      for (Eigen::Index k = 0; k < lines; ++k) {
        rw[2 * k] = weight(k, j);
        rw[2 * k + 1] = weight(k, j);
      }
      Eigen::VectorXd y(2 * lines);
      for (Eigen::Index k = 0; k < lines; ++k) {
        y[2 * k] = h(k, j).real();
        y[2 * k + 1] = h(k, j).imag();
      }
      const Eigen::MatrixXd aw = rw.asDiagonal() * design;
      const Eigen::VectorXd yw = rw.cwiseProduct(y);
      const Eigen::VectorXd x = aw.colPivHouseholderQr().solve(yw);
      r.segment(2 * lines * j, 2 * lines) = aw * x - yw;
      if (coefficients) coefficients->col(j) = x;
    }
    return true;
  }
};

}  // namespace

namespace {

// The band given, or 0.6x the lowest to 1.4x the highest start frequency where it is not.
void FitBand(const std::vector<Peak>& start, const CurveFitOptions& options, double& lo,
             double& hi) {
  lo = options.freq_min_hz;
  hi = options.freq_max_hz;
  double fmin = start.front().freq_hz;
  double fmax = start.front().freq_hz;
  for (const Peak& p : start) {
    fmin = std::min(fmin, p.freq_hz);
    fmax = std::max(fmax, p.freq_hz);
  }
  if (lo == 0.0) lo = 0.6 * fmin;
  if (hi == 0.0) hi = 1.4 * fmax;
}

// The lines of the band with their weights, and the start poles as the parameter scale.
FitProblem MakeFitProblem(const Frf& receptance, const std::vector<Peak>& start,
                          const CurveFitOptions& options, double lo, double hi) {
  FitProblem prob;
  prob.residual_terms = options.residual_terms;
  std::vector<Eigen::Index> rows;
  for (Eigen::Index k = 0; k < receptance.freq_hz.size(); ++k) {
    const double f = receptance.freq_hz[k];
    if (f > 0.0 && f >= lo && f <= hi) rows.push_back(k);
  }
  const auto lines = static_cast<Eigen::Index>(rows.size());
  const Eigen::Index nresp = receptance.h.cols();
  const auto nmodes = static_cast<Eigen::Index>(start.size());
  Require(lines * 2 > 2 * nmodes + 2 + 2 * nmodes,
          "curve fit: too few frequency lines in the band");
  prob.omega.resize(lines);
  prob.h.resize(lines, nresp);
  prob.weight.resize(lines, nresp);
  for (Eigen::Index k = 0; k < lines; ++k) {
    const Eigen::Index src = rows[static_cast<std::size_t>(k)];
    prob.omega[k] = 2.0 * std::numbers::pi * receptance.freq_hz[src];
    for (Eigen::Index j = 0; j < nresp; ++j) {
      const std::complex<double> v = receptance.h(src, j);
      prob.h(k, j) = v;
      const double coh = options.coherence_weighting ? receptance.coherence(src, j) : 1.0;
      // Relative misfit: resonance and the lines between modes count alike.
      prob.weight(k, j) = std::abs(v) > 0.0 ? std::sqrt(std::max(coh, 0.0)) / std::abs(v) : 0.0;
    }
  }
  prob.omega0.resize(nmodes);
  for (Eigen::Index i = 0; i < nmodes; ++i)
    prob.omega0[i] = start[static_cast<std::size_t>(i)].omega_rad_s;
  return prob;
}

Eigen::VectorXd StartParameters(const std::vector<Peak>& start) {
  const auto nmodes = static_cast<Eigen::Index>(start.size());
  Eigen::VectorXd params(2 * nmodes);
  for (Eigen::Index i = 0; i < nmodes; ++i) {
    params[2 * i] = 0.0;
    params[2 * i + 1] = std::log(std::clamp(start[static_cast<std::size_t>(i)].zeta, 1e-5, 0.5));
  }
  return params;
}

// Modes (in frequency order), residual terms and misfit of the solution at `params`.
void StoreFit(const FitProblem& prob, const Eigen::VectorXd& params, const Eigen::VectorXd& r,
              const Eigen::MatrixXd& coef, double exp_window_tau_s, CurveFitResult& result) {
  const Eigen::Index nmodes = prob.modes();
  const Eigen::Index nresp = prob.h.cols();
  Eigen::VectorXd om;
  Eigen::VectorXd ze;
  prob.Poles(params, om, ze);
  double weight_sum = 0.0;
  for (Eigen::Index k = 0; k < prob.weight.size(); ++k)
    weight_sum += 2.0 * prob.weight(k) * prob.weight(k) * std::norm(prob.h(k));
  result.rms_relative_error = weight_sum > 0.0 ? std::sqrt(r.squaredNorm() / weight_sum) : 0.0;
  for (Eigen::Index i = 0; i < nmodes; ++i) {
    FittedMode m;
    m.omega_rad_s = om[i];
    m.freq_hz = om[i] / (2.0 * std::numbers::pi);
    m.zeta = CorrectExponentialWindowDamping(ze[i], om[i], exp_window_tau_s);
    m.residues.resize(nresp);
    for (Eigen::Index j = 0; j < nresp; ++j)
      m.residues[j] = std::complex<double>(coef(i, j), coef(nmodes + i, j));
    result.modes.push_back(m);
  }
  std::sort(result.modes.begin(), result.modes.end(),
            [](const FittedMode& a, const FittedMode& b) { return a.omega_rad_s < b.omega_rad_s; });
  result.lower_residual = Eigen::VectorXd::Zero(nresp);
  result.upper_residual = Eigen::VectorXd::Zero(nresp);
  if (prob.residual_terms) {
    result.lower_residual = coef.row(2 * nmodes).transpose();
    result.upper_residual = coef.row(2 * nmodes + 1).transpose();
  }
}

CurveFitResult FitModesImpl(const Frf& receptance, const std::vector<Peak>& start,
                            const CurveFitOptions& options, bool hold_poles) {
  options.Validate();
  Require(receptance.quantity == Quantity::kDisplacement, "curve fit needs a receptance FRF");
  Require(!start.empty(), "curve fit needs at least one starting mode (no peaks were found)");
  double lo = 0.0;
  double hi = 0.0;
  FitBand(start, options, lo, hi);
  const FitProblem prob = MakeFitProblem(receptance, start, options, lo, hi);
  Eigen::VectorXd params = StartParameters(start);
  const numerics::ResidualOnlyFunction f = [&prob](const Eigen::VectorXd& p, Eigen::VectorXd& r) {
    return prob.Solve(p, r, nullptr);
  };
  CurveFitResult result;
  result.freq_min_hz = lo;
  result.freq_max_hz = hi;
  if (hold_poles) {
    result.summary.termination = numerics::TerminationType::kFunctionTolerance;
    result.summary.message = "linear least squares with the poles held";
  } else {
    result.summary = numerics::LevenbergMarquardt(numerics::NumericDiff(f), params, options.solver);
  }

  Eigen::VectorXd r;
  Eigen::MatrixXd coef;
  if (!prob.Solve(params, r, &coef)) {
    result.summary.termination = numerics::TerminationType::kNumericalFailure;
    result.summary.message = "fitted poles left the physical domain";
    return result;
  }
  StoreFit(prob, params, r, coef, receptance.exp_window_tau_s, result);
  return result;
}

}  // namespace

CurveFitResult FitModes(const Frf& receptance, const std::vector<Peak>& start,
                        const CurveFitOptions& options) {
  return FitModesImpl(receptance, start, options, false);
}

CurveFitResult FitResidues(const Frf& receptance, const std::vector<double>& omega_rad_s,
                           const std::vector<double>& zeta, const CurveFitOptions& options) {
  options.Validate();
  Require(receptance.quantity == Quantity::kDisplacement, "residue fit needs a receptance FRF");
  Require(!omega_rad_s.empty() && omega_rad_s.size() == zeta.size(),
          "residue fit needs one damping per pole");
  std::vector<Peak> start;
  for (std::size_t i = 0; i < omega_rad_s.size(); ++i) {
    Peak p;
    p.omega_rad_s = omega_rad_s[i];
    p.freq_hz = omega_rad_s[i] / (2.0 * std::numbers::pi);
    p.zeta = zeta[i];
    start.push_back(p);
  }
  return FitModesImpl(receptance, start, options, true);
}

std::vector<ModeEstimate> ShapesFromResidues(const CurveFitResult& fit, std::size_t driving_point) {
  std::vector<ModeEstimate> modes;
  for (const FittedMode& f : fit.modes) {
    Require(driving_point < static_cast<std::size_t>(f.residues.size()),
            "driving-point response out of range");
    const auto p = static_cast<Eigen::Index>(driving_point);
    const std::complex<double> app = f.residues[p];
    ModeEstimate m;
    m.omega_rad_s = f.omega_rad_s;
    m.freq_hz = f.freq_hz;
    m.zeta = f.zeta;
    const double phi_p = std::sqrt(std::abs(app));
    m.shape.resize(f.residues.size());
    for (Eigen::Index j = 0; j < f.residues.size(); ++j) {
      // Projection of A_jp on the direction of A_pp: real for real modes, robust for slightly
      // complex ones.
      const double proj =
          std::abs(app) > 0.0 ? std::real(f.residues[j] * std::conj(app)) / std::abs(app) : 0.0;
      m.shape[j] = phi_p > 0.0 ? proj / phi_p : 0.0;
    }
    m.ratio = Ratio(m.shape);
    SetShapeRatios(m, p);
    modes.push_back(m);
  }
  return modes;
}

Eigen::VectorXcd ModalReceptance(const CurveFitResult& fit, double omega_rad_s) {
  const Eigen::Index nresp = fit.lower_residual.size();
  Eigen::VectorXcd h = Eigen::VectorXcd::Zero(nresp);
  for (const FittedMode& m : fit.modes) {
    const std::complex<double> den(m.omega_rad_s * m.omega_rad_s - omega_rad_s * omega_rad_s,
                                   2.0 * m.zeta * m.omega_rad_s * omega_rad_s);
    h += m.residues / den;
  }
  for (Eigen::Index j = 0; j < nresp; ++j) {
    h[j] += -fit.lower_residual[j] / (omega_rad_s * omega_rad_s) + fit.upper_residual[j];
  }
  return h;
}

ModeMethod ParseModeMethod(std::string_view name) {
  if (name == "peaks" || name == "peak-picking") return ModeMethod::kPeakPicking;
  if (name == "fit" || name == "curve-fit") return ModeMethod::kCurveFit;
  if (name == "lscf" || name == "polymax") return ModeMethod::kLscf;
  if (name == "lsce") return ModeMethod::kLsce;
  throw InputError("unknown mode method '" + std::string(name) +
                   "' (known: lscf, lsce, fit, peaks)");
}

namespace {

// The band modes are sought in: the one given (--fmin-hz/--fmax-hz), else, on an impact FRF, up
// to where the hammer's force still excites the structure (Frf::force_band_max_hz). Above it
// H1 is the record's noise over the pulse's vanishing force: a four-mass chain's 12-bit record
// showed 60-1300 "clear peaks" at 650-730 Hz, each named as a peak without a mode, and the poles
// the automatic bands placed there could take a real mode's place among the strongest.
PeakOptions AnalysedBand(const Frf& receptance, const PeakOptions& given) {
  PeakOptions p = given;
  if (p.freq_max_hz == 0.0 && receptance.force_band_max_hz > p.freq_min_hz)
    p.freq_max_hz = receptance.force_band_max_hz;
  return p;
}

StabilizationOptions DiagramOptions(const ModeIdentificationOptions& options) {
  StabilizationOptions so = options.stabilization;
  so.method = options.method == ModeMethod::kLscf ? PoleMethod::kLscf : PoleMethod::kLsce;
  so.freq_min_hz = options.peaks.freq_min_hz;
  so.freq_max_hz = options.peaks.freq_max_hz;
  return so;
}

StabilizationDiagram DiagramForReceptance(const Frf& receptance,
                                          const ModeIdentificationOptions& options,
                                          const StabilizationOptions& so) {
  if (so.freq_max_hz > 0.0) return BuildStabilizationDiagram(receptance, so);
  // No band given: bands around the resonances the peak picker sees (see AutomaticBands). Every
  // peak places a band: a limit on the modes keeps the poles seen at the most orders
  // (StrongestPoles), it does not choose where to look (the largest peaks of a single-hit FRF can
  // be noise at the force spectrum's notches, above a weak mode).
  // Only where the force excites the structure (AnalysedBand).
  PeakOptions look = AnalysedBand(receptance, options.peaks);
  look.max_peaks = 0;
  const PeakResult seen =
      PickPeaks(receptance.freq_hz, PickingMagnitude(receptance, options.picking_column), look);
  std::vector<double> at;
  for (const Peak& p : seen.peaks) at.push_back(p.freq_hz);
  // The bands around those peaks reach beyond it as before (1.6 times the highest, within the
  // lines): a mode near the force band's top keeps the lines above it in its fit.
  std::vector<std::pair<double, double>> bands =
      AutomaticBands(at, receptance.freq_hz[receptance.freq_hz.size() - 1]);
  for (auto& b : bands) b.first = std::max(b.first, so.freq_min_hz);
  return BuildStabilizationDiagram(receptance, so, bands);
}

// At most `max_poles` (0: all) of the diagram's poles, in frequency order: the poles seen at the
// most orders.
std::vector<SelectedPole> StrongestPoles(std::vector<SelectedPole> chosen, std::size_t max_poles) {
  if (max_poles > 0 && chosen.size() > max_poles) {
    std::stable_sort(
        chosen.begin(), chosen.end(),
        [](const SelectedPole& a, const SelectedPole& b) { return a.orders > b.orders; });
    chosen.resize(max_poles);
    std::sort(chosen.begin(), chosen.end(),
              [](const SelectedPole& a, const SelectedPole& b) { return a.freq_hz < b.freq_hz; });
  }
  return chosen;
}

// The default must not leave a user with nothing: LSCE next (it holds up on short Welch FRFs
// where pLSCF finds no stable pole, e.g. the DaISy robot arm), then the curve fit; each step says
// why the one before gave no mode, and when none does the refusal names all three causes.
ModeIdentification IdentifyWithoutPlscf(const Frf& receptance, std::size_t driving_point,
                                        const ModeIdentificationOptions& options,
                                        const std::string& why) {
  ModeIdentificationOptions next = options;
  next.stabilization_fallback_off = true;
  next.method = ModeMethod::kLsce;
  ModeIdentification alt;
  try {
    alt = IdentifyModes(receptance, driving_point, next);
    alt.warnings.insert(alt.warnings.begin(), why + ": modes from LSCE");
    return alt;
  } catch (const InputError& lsce) {
    next.method = ModeMethod::kCurveFit;
    try {
      alt = IdentifyModes(receptance, driving_point, next);
    } catch (const InputError& fit) {
      throw InputError("no modes: " + why + "; " + lsce.what() + "; curve fit: " + fit.what());
    }
    alt.warnings.insert(alt.warnings.begin(),
                        why + "; " + lsce.what() + ": modes from the curve fit (no intervals)");
  }
  return alt;
}

// FitResidues models the damping the FRF shows: the exponential-window correction undone.
std::vector<double> DampingShownByFrf(const Frf& receptance,
                                      const std::vector<SelectedPole>& chosen) {
  std::vector<double> ze;
  for (const SelectedPole& p : chosen) {
    ze.push_back(receptance.exp_window_tau_s > 0.0
                     ? p.zeta + 1.0 / (receptance.exp_window_tau_s * p.omega_rad_s)
                     : p.zeta);
  }
  return ze;
}

void FitResiduesAtPoles(const Frf& receptance, std::size_t driving_point,
                        const CurveFitOptions& fit_options, const std::vector<SelectedPole>& chosen,
                        const std::vector<double>& om, const std::vector<double>& ze,
                        ModeIdentification& out) {
  CurveFitOptions fo = fit_options;
  // Residues over 0.6x the lowest to 1.4x the highest chosen pole (FitModes' automatic band):
  // the lines far below the first mode hold accelerometer noise divided by omega^2.
  fo.freq_min_hz = 0.0;
  fo.freq_max_hz = 0.0;
  out.fit = FitResidues(receptance, om, ze, fo);
  out.fitted = true;
  out.modes = ShapesFromResidues(out.fit, driving_point);
  for (std::size_t i = 0; i < out.modes.size() && i < chosen.size(); ++i)
    out.modes[i].zeta = chosen[i].zeta;
}

// The chosen poles start a weighted least-squares fit of the pole-residue model (see
// modal_model.hpp), which gives omega, zeta and the shape directions with their covariance.
// The diagram's poles are medians over model orders, and the pLSCF numerators at low orders
// carry the model's misfit into the shapes (1-4 % in a1/a2 at orders 6-12 on a noise-free
// synthetic 2-DOF test, +0.8 % on average over the default orders with 0.5 % noise); the
// refined model has neither bias. The residue fit still supplies the driving-point scale.
void FitModelFromPoles(const Frf& receptance, const std::vector<double>& om,
                       const std::vector<double>& ze, double freq_tolerance,
                       ModeIdentification& out) {
  std::vector<std::complex<double>> start;
  for (std::size_t i = 0; i < om.size(); ++i) {
    start.emplace_back(-ze[i] * om[i], om[i] * std::sqrt(std::max(0.0, 1.0 - ze[i] * ze[i])));
  }
  try {
    out.model = FitModalModel(receptance, start, {});
    out.has_model = true;
  } catch (const InputError& e) {
    out.warnings.push_back(std::string("no confidence intervals: ") + e.what());
  }
  if (!out.has_model) return;
  bool moved = false;
  for (std::size_t i = 0; i < out.modes.size(); ++i) {
    const auto ii = static_cast<Eigen::Index>(i);
    // A refinement that walks away from the diagram's pole found another minimum (a pole
    // swapped with its neighbour, or absorbed by noise): keep the diagram's values.
    moved = moved ||
            std::abs(out.model.omega_rad_s[ii] - out.modes[i].omega_rad_s) >
                freq_tolerance * out.modes[i].omega_rad_s ||
            !(std::abs(out.model.zeta[ii] - out.modes[i].zeta) <= 0.5 * out.modes[i].zeta);
  }
  if (moved || !out.model.summary.Converged()) {
    out.warnings.push_back(
        "the modal model fit moved away from the diagram's poles: modes from the diagram, no "
        "confidence intervals");
    out.has_model = false;
  }
}

// The modal model's omega, zeta and shape ratios with their intervals, each where the model
// determines it; elsewhere the diagram's pole or the residue fit's shape stays, without an
// interval, and a warning says so.
void ModesFromModel(std::size_t driving_point, ModeIdentification& out) {
  const auto p = static_cast<Eigen::Index>(driving_point);
  if (!out.model.note.empty()) out.warnings.push_back(out.model.note);
  for (std::size_t i = 0; i < out.modes.size(); ++i) {
    const auto ii = static_cast<Eigen::Index>(i);
    ModeEstimate& m = out.modes[i];
    char line[200];
    const double sd_omega = out.model.omega_sd_rad_s[ii];
    const double sd_zeta = out.model.zeta_sd[ii];
    // Without the ringing terms the values stand but the covariance misses the ringing.
    const bool intervals = !out.model.ringing_terms_dropped;
    if (std::isfinite(sd_omega) && std::isfinite(sd_zeta)) {
      m.omega_rad_s = out.model.omega_rad_s[ii];
      m.freq_hz = m.omega_rad_s / (2.0 * std::numbers::pi);
      m.zeta = out.model.zeta[ii];
      if (intervals) {
        m.omega_ci95_rad_s = NormalInterval95(m.omega_rad_s, sd_omega);
        m.zeta_ci95 = NormalInterval95(m.zeta, sd_zeta);
      }
    } else {
      std::snprintf(line, sizeof line,
                    "mode at %.5g Hz: the modal model does not determine its pole from these "
                    "lines: omega and zeta from the diagram, no interval",
                    m.freq_hz);
      out.warnings.emplace_back(line);
    }
    // Shape ratios phi_j / phi_p from the model's residue projections, each with its interval
    // where the model determines it (else the residue fit's shape stays, without one).
    bool undetermined = false;
    std::string disagree;
    for (Eigen::Index j = 0; j < m.shape.size(); ++j) {
      if (j == p) continue;
      const double q = out.model.ShapeRatio(ii, j, p);
      const double sd = out.model.ShapeRatioSd(ii, j, p);
      if (!std::isfinite(sd)) {
        undetermined = true;
        continue;
      }
      // The residue fit with the same poles (no ringing terms, the modal form) is a second
      // estimate of the same ratio. Where the two disagree by more than three of the model's
      // standard deviations and 10 %, the model's ringing terms have absorbed part of the hit's
      // own response (records that end, or start, in strong ringing: the pretrigger's phase
      // hardly turns across the mode, and R_i and S_i trade places), and its interval is not to
      // be trusted: the residue fit's ratio stays, without an interval, and the mode says so.
      // (Short records with three hits gave a1/a2 0.03 and -0.11 for 0.568 and -1.481, with
      // intervals covering 35-52 % of the seeds.)
      // An interval wider than a quarter of the ratio says the same: the lines do not pin the
      // shape down (three-mass chain, hits 5 s apart: modes 2 and 3 at a third of their ratios
      // with intervals of that size).
      const double r_fit = m.shape[p] != 0.0 ? m.shape[j] / m.shape[p] : q;
      const bool apart =
          std::abs(q - r_fit) > std::max(3.0 * sd, 0.1 * std::max(std::abs(q), std::abs(r_fit)));
      const bool loose = kZ95 * sd > 0.25 * std::abs(q);
      if (apart || loose) {
        char part[200];
        std::snprintf(part, sizeof part,
                      "%sphi%d/phi%d %.4g +- %.2g (modal model) against %.4g (residue fit)",
                      disagree.empty() ? "" : ", ", static_cast<int>(j) + 1,
                      static_cast<int>(p) + 1, q, kZ95 * sd, r_fit);
        disagree += part;
        continue;
      }
      m.shape[j] = m.shape[p] * q;
      m.shape_ratio[j] = q;
      if (intervals) m.shape_ratio_ci95[static_cast<std::size_t>(j)] = NormalInterval95(q, sd);
      // ratio = phi_0 / phi_1: the projection itself when the hammer is at 1, its inverse at 0.
      if (m.shape.size() == 2 && intervals)
        m.ratio_ci95 = NormalInterval95(p == 1 ? q : 1.0 / q, p == 1 ? sd : sd / (q * q));
    }
    m.ratio = Ratio(m.shape);
    if (!disagree.empty()) {
      m.caution += (m.caution.empty() ? "" : "; ") +
                   ("shape not resolved: " + disagree +
                    " (apart by more than 3 sd and 10 %, or an interval wider than a quarter of "
                    "the ratio): ringing the records hold (hits closer than the ring-down) is "
                    "not told from the hit's response; shape from the residue fit, no interval; "
                    "hits further apart (longer records) give both");
      std::snprintf(line, sizeof line, "mode at %.5g Hz: ", m.freq_hz);
      out.warnings.push_back(line + m.caution);
    }
    if (undetermined) {
      std::snprintf(line, sizeof line,
                    "mode at %.5g Hz: the modal model does not determine its shape from these "
                    "lines: shape from the residue fit, no interval on %s",
                    m.freq_hz, m.shape.size() == 2 ? "a1/a2" : "some shape ratios");
      out.warnings.emplace_back(line);
    }
  }
}

ModeIdentification IdentifyFromDiagram(const Frf& receptance, std::size_t driving_point,
                                       const ModeIdentificationOptions& options) {
  ModeIdentification out;
  const StabilizationOptions so = DiagramOptions(options);
  const bool may_fall_back =
      options.method == ModeMethod::kLscf && !options.stabilization_fallback_off;
  try {
    out.diagram = DiagramForReceptance(receptance, options, so);
  } catch (const InputError& e) {
    if (!may_fall_back) throw;
    return IdentifyWithoutPlscf(receptance, driving_point, options, e.what());
  }
  out.has_diagram = true;
  const std::vector<SelectedPole> chosen =
      StrongestPoles(out.diagram.selected, options.peaks.max_peaks);
  const std::string orders = out.diagram.orders.empty()
                                 ? std::string("none")
                                 : std::to_string(out.diagram.orders.front()) + ".." +
                                       std::to_string(out.diagram.orders.back());
  if (chosen.empty() && may_fall_back) {
    return IdentifyWithoutPlscf(receptance, driving_point, options,
                                "lscf: no stable pole in the diagram (orders " + orders + ")");
  }
  Require(!chosen.empty(), std::string("no stable pole in the stabilization diagram (") +
                               PoleMethodName(so.method) + ", orders " + orders +
                               "): raise the orders (--orders), narrow the band, or use "
                               "--method fit");
  std::vector<double> om;
  for (const SelectedPole& p : chosen) om.push_back(p.omega_rad_s);
  const std::vector<double> ze = DampingShownByFrf(receptance, chosen);
  FitResiduesAtPoles(receptance, driving_point, options.fit, chosen, om, ze, out);
  FitModelFromPoles(receptance, om, ze, so.freq_tolerance, out);
  if (out.has_model) ModesFromModel(driving_point, out);
  return out;
}

// Peak picks stand in for a curve fit that failed: half-power damping and Eq. 10 shapes are
// biased by leakage, neighbouring modes and the resolution (17 % off in frequency on a double-hit
// record), so every mode says so, with the way out.
void MarkPeakPicksUnreliable(const std::string& why, ModeIdentification& out) {
  for (ModeEstimate& m : out.modes) {
    m.unreliable = true;
    m.caution = why +
                ": peak-picking estimate, unreliable (half-power damping and peak shapes); "
                "narrow the band around the mode (--fmin-hz/--fmax-hz), give orders (--orders) "
                "or a longer record with clean hits";
  }
}

// A peak's magnitude over the median of the lines around it (20 each side, its own 5 left out).
double Prominence(const Eigen::VectorXd& magnitude, const Peak& pk) {
  constexpr Eigen::Index kAround = 20;
  const auto at = static_cast<Eigen::Index>(pk.line);
  std::vector<double> near;
  for (Eigen::Index k = std::max<Eigen::Index>(0, at - kAround);
       k <= std::min<Eigen::Index>(magnitude.size() - 1, at + kAround); ++k)
    if (std::abs(k - at) > 2) near.push_back(magnitude[k]);
  if (near.empty()) return 0.0;
  std::nth_element(near.begin(), near.begin() + static_cast<std::ptrdiff_t>(near.size() / 2),
                   near.end());
  const double median = near[near.size() / 2];
  return median > 0.0 ? magnitude[at] / median : std::numeric_limits<double>::infinity();
}

// Whether a peak stands above its neighbourhood (its magnitude `prominence` times their median)
// by more than kNoiseErrors times the random error of |H| at it: sqrt(1 - g2) / (sqrt(g2) *
// sqrt(2 n)) over n averages (Bendat & Piersol, Random Data, 4th ed., table 9.6), g2 the least
// coherence over the peak's five lines (a resonance's is high across them; with 2 averages noise
// alone reads anywhere in [0, 1] on one line), its bias (1 - g2) / n for n averages taken off
// (noise alone reads 1/n on average). With 2 or 3 hits the receptance's low edge (noise over
// omega^2) and the record's noise make bumps hundreds of times their neighbourhood (0.15 and
// 0.37 Hz on an 11 s record, 2.19 Hz on a 3.2 s one) whose coherence, unbiased, is 0-0.4: their
// error is larger than their height. A resonance's is a fifth of it or less.
bool ClearOfNoise(const Frf& receptance, int picking_column, const Peak& pk, double prominence) {
  constexpr double kNoiseErrors = 3.0;
  const auto n = static_cast<double>(receptance.averages);
  if (n < 2.0 || receptance.coherence.rows() != receptance.h.rows()) return true;
  const auto at = static_cast<Eigen::Index>(pk.line);
  double g2 = 1.0;
  for (Eigen::Index k = std::max<Eigen::Index>(0, at - 2);
       k <= std::min<Eigen::Index>(receptance.coherence.rows() - 1, at + 2); ++k)
    g2 = std::min(g2, picking_column >= 0 ? receptance.coherence(k, picking_column)
                                          : receptance.coherence.row(k).mean());
  g2 = std::clamp((n * g2 - 1.0) / (n - 1.0), 0.0, 1.0);
  if (!(g2 > 0.0)) return false;
  const double error = std::sqrt(1.0 - g2) / (std::sqrt(g2) * std::sqrt(2.0 * n));
  const double rise = prominence > 0.0 ? 1.0 - 1.0 / prominence : 0.0;
  return rise > kNoiseErrors * error;
}

ModeIdentification IdentifyFromPeaks(const Frf& receptance, std::size_t driving_point,
                                     const ModeIdentificationOptions& options) {
  ModeIdentification out;
  const Eigen::VectorXd mag = PickingMagnitude(receptance, options.picking_column);
  const PeakResult all = PickPeaks(receptance.freq_hz, mag, AnalysedBand(receptance, options.peaks),
                                   receptance.exp_window_tau_s);
  // Peaks no higher than the FRF's random error are noise, not modes: on records of 9-11 s and
  // 2 hits the receptance's low band (the response's noise over omega^2) gave dozens of them
  // below 13 Hz, each a mode of the list and a pole of the curve fit.
  PeakResult picked;
  picked.warnings = all.warnings;
  for (const Peak& pk : all.peaks)
    if (ClearOfNoise(receptance, options.picking_column, pk, Prominence(mag, pk)))
      picked.peaks.push_back(pk);
  Require(!picked.peaks.empty(),
          "no resonance found in the FRF (check the band and the threshold)");
  out.peaks = picked.peaks;
  out.warnings = picked.warnings;
  out.modes = ShapesFromPeaks(receptance, driving_point, picked.peaks);
  constexpr std::size_t kMaxFittedModes = 12;
  if (options.method == ModeMethod::kCurveFit && picked.peaks.size() > kMaxFittedModes) {
    out.warnings.push_back(std::to_string(picked.peaks.size()) +
                           " peaks are too many for one curve fit; modes are the peak-picking "
                           "estimates (narrow the band, "
                           "raise the threshold or limit the number of modes)");
    MarkPeakPicksUnreliable(
        std::to_string(picked.peaks.size()) + " peaks are too many for one curve fit", out);
  } else if (options.method == ModeMethod::kCurveFit) {
    out.fit = FitModes(receptance, picked.peaks, options.fit);
    out.fitted = true;
    if (out.fit.summary.Converged()) {
      out.modes = ShapesFromResidues(out.fit, driving_point);
      // The fit uses every line of the band, not the half-power points: resolution warnings of
      // the peak picks no longer apply.
      out.warnings.clear();
    } else {
      out.warnings.push_back("curve fit did not converge (" + out.fit.summary.message +
                             "); modes are the peak-picking estimates");
      MarkPeakPicksUnreliable("the curve fit did not converge (" + out.fit.summary.message + ")",
                              out);
    }
  }
  return out;
}

// A pole with no resolved damping is a numerical artefact (a zero-width peak, or a fit that
// drove the damping to zero), or a pole the record cannot tell from an undamped one (its 95 %
// interval on zeta reaches 0): not a mode.
void DropUnresolvedModes(ModeIdentification& out) {
  constexpr double kMinResolvedZeta = 1e-6;
  std::vector<ModeEstimate> kept;
  for (const ModeEstimate& m : out.modes) {
    const bool interval_reaches_zero = std::isfinite(m.zeta_ci95[0]) && m.zeta_ci95[0] <= 0.0;
    if (m.zeta > kMinResolvedZeta && std::isfinite(m.zeta) && !interval_reaches_zero) {
      kept.push_back(m);
      continue;
    }
    char line[200];
    if (interval_reaches_zero) {
      std::snprintf(line, sizeof line,
                    "pole at %.5g Hz dropped: its damping is not resolved (zeta = %.3g, 95 %% "
                    "interval %.3g..%.3g reaches 0)",
                    m.freq_hz, m.zeta, m.zeta_ci95[0], m.zeta_ci95[1]);
    } else {
      std::snprintf(line, sizeof line,
                    "pole at %.5g Hz dropped: its damping is not resolved (zeta = %.3g)", m.freq_hz,
                    m.zeta);
    }
    out.warnings.emplace_back(line);
    out.dropped.push_back(m);
  }
  out.modes = std::move(kept);
  if (out.modes.empty())
    throw InputError("no mode with a resolved damping in the FRF: " + out.warnings.back());
}

// An exponential window of time constant tau adds the decay rate 1/tau to every mode; the damping
// is corrected for it, but a mode whose own decay rate zeta omega is smaller than that has a peak
// widened more than twice over (a lightly damped slow mode sinks into the noise and may be lost)
// and a damping that is the small difference of the window's and the measured one. Said per
// mode, with the way out: a longer record and no window.
void NameWindowDampingOverOwn(double exp_window_tau_s, ModeIdentification& out) {
  if (!(exp_window_tau_s > 0.0)) return;
  const double added_1_s = 1.0 / exp_window_tau_s;
  for (const ModeEstimate& m : out.modes) {
    const double own_1_s = m.zeta * m.omega_rad_s;
    if (!(own_1_s > 0.0) || added_1_s <= own_1_s) continue;
    char line[400];
    std::snprintf(line, sizeof line,
                  "mode at %.5g Hz: the exponential window adds %.2g times its own damping "
                  "(decay rate %.3g 1/s against its %.3g 1/s): its peak is %.2g times as wide "
                  "and its damping what is left after the window's is subtracted, and a slower "
                  "or weaker mode may be lost; longer records without the window",
                  m.freq_hz, added_1_s / own_1_s, added_1_s, own_1_s, 1.0 + added_1_s / own_1_s);
    out.warnings.emplace_back(line);
  }
  for (const ModeEstimate& m : out.dropped) {
    if (m.zeta > 0.0 || !std::isfinite(m.zeta)) continue;
    char line[400];
    std::snprintf(line, sizeof line,
                  "pole at %.5g Hz: the exponential window's added damping (decay rate %.3g 1/s) "
                  "is all the damping its peak shows: a lightly damped mode lost under the "
                  "window; longer records without the window",
                  m.freq_hz, added_1_s);
    out.warnings.emplace_back(line);
  }
}

// Above the force's band (AnalysedBand) peaks are not named one by one; one line says the band
// ends there, when that part holds clear peaks by the band's measure (coherent, at least 5 % of
// the band's largest peak): the largest of them and the option that searches it.
void NameBandAboveTheForce(const Frf& receptance, const ModeIdentificationOptions& options,
                           const PeakOptions& look, const Eigen::VectorXd& magnitude,
                           const PeakResult& seen, ModeIdentification& out) {
  constexpr double kClearFraction = 0.05;
  constexpr double kMinCoherence = 0.5;
  if (options.peaks.freq_max_hz > 0.0 || !(look.freq_max_hz > 0.0) || seen.peaks.empty()) return;
  double largest = 0.0;
  for (const Peak& p : seen.peaks)
    largest = std::max(largest, magnitude[static_cast<Eigen::Index>(p.line)]);
  Eigen::Index at = -1;
  for (Eigen::Index k = 1; k + 1 < receptance.freq_hz.size(); ++k) {
    if (receptance.freq_hz[k] <= look.freq_max_hz) continue;
    const double coh = options.picking_column >= 0 ? receptance.coherence(k, options.picking_column)
                                                   : receptance.coherence.row(k).mean();
    if (coh < kMinCoherence || magnitude[k] < kClearFraction * largest) continue;
    if (magnitude[k] < magnitude[k - 1] || magnitude[k] < magnitude[k + 1]) continue;
    if (at < 0 || magnitude[k] > magnitude[at]) at = k;
  }
  if (at < 0) return;
  char line[360];
  std::snprintf(line, sizeof line,
                "modes are sought up to %.4g Hz, the band where the hammer's force excites the "
                "rig; above it the FRF's peaks (the largest at %.5g Hz) are the record's noise "
                "over a vanishing force, not named one by one (--fmax-hz searches beyond; a "
                "harder hammer tip excites higher)",
                look.freq_max_hz, receptance.freq_hz[at]);
  // The fallback chain identifies again through IdentifyModes: said once.
  if (std::find(out.warnings.begin(), out.warnings.end(), line) == out.warnings.end())
    out.warnings.emplace_back(line);
}

// A resonance the data show but no mode explains must not vanish silently (a diagram whose
// orders are too low for the band, a band cut through a mode): each clear peak of the band
// farther from every mode than its half-power width (and two lines, and 2 %) is named. A peak
// where the responses are mostly noise (coherence below one half at its line, over the columns
// picked) is no resonance the data show: a hammer test's band above its force's roll-off is full
// of them.
void NamePeaksWithoutMode(const Frf& receptance, const ModeIdentificationOptions& options,
                          ModeIdentification& out) {
  constexpr double kClearFraction = 0.05;
  constexpr double kMinLines = 2.0;
  constexpr double kMinCoherence = 0.5;
  const auto coherent = [&](const Peak& pk) {
    const auto line = static_cast<Eigen::Index>(pk.line);
    if (options.picking_column >= 0)
      return receptance.coherence(line, options.picking_column) >= kMinCoherence;
    return receptance.coherence.row(line).mean() >= kMinCoherence;
  };
  PeakOptions look = AnalysedBand(receptance, options.peaks);
  look.max_peaks = 0;
  look.threshold_fraction = std::max(look.threshold_fraction, kClearFraction);
  const Eigen::VectorXd magnitude = PickingMagnitude(receptance, options.picking_column);
  PeakResult seen;
  try {
    seen = PickPeaks(receptance.freq_hz, magnitude, look);
  } catch (const InputError&) {
    return;  // no band to look in: the modes came from elsewhere
  }
  NameBandAboveTheForce(receptance, options, look, magnitude, seen, out);
  // "Clear" also against the largest resonance where the force excites the rig, not only the
  // band given: a band that leaves the largest mode out (--fmin-hz above it) made the encoders'
  // noise at 300-500 Hz clear (230 peaks named on a four-mass chain).
  double largest = 0.0;
  if (options.peaks.freq_min_hz > 0.0 || options.peaks.freq_max_hz > 0.0) {
    PeakOptions whole;
    whole.freq_max_hz = receptance.force_band_max_hz;
    try {
      for (const Peak& p : PickPeaks(receptance.freq_hz, magnitude, whole).peaks)
        largest = std::max(largest, p.magnitude);
    } catch (const InputError&) {
      largest = 0.0;
    }
  }
  const double spacing =
      receptance.freq_hz.size() > 1
          ? (receptance.freq_hz[receptance.freq_hz.size() - 1] - receptance.freq_hz[0]) /
                static_cast<double>(receptance.freq_hz.size() - 1)
          : 0.0;
  const auto explained = [&](const Peak& pk, const std::vector<ModeEstimate>& modes) {
    const double width = (pk.omega_b_rad_s - pk.omega_a_rad_s) / (2.0 * std::numbers::pi);
    const double tol = std::max({width, 2.0 * spacing, 0.02 * pk.freq_hz});
    return std::any_of(modes.begin(), modes.end(), [&](const ModeEstimate& m) {
      return std::abs(m.freq_hz - pk.freq_hz) <= tol;
    });
  };
  // A resonance narrower than a line (zeta 0.0003 at 167.8 Hz in lines 0.31 Hz apart) has no
  // half-power band of 2 lines, yet it stands far above its neighbourhood; a noise bump of 2
  // lines does not. Such a peak is named when prominent (its magnitude over the median of the
  // lines around it), and the band's largest peak always: the largest resonance is never left
  // out without a word. Named peaks come most prominent first.
  constexpr double kProminent = 10.0;
  const auto prominence = [&](const Peak& pk) { return Prominence(magnitude, pk); };
  double band_largest = 0.0;
  for (const Peak& pk : seen.peaks) band_largest = std::max(band_largest, pk.magnitude);
  std::vector<std::pair<double, const Peak*>> named;
  for (const Peak& pk : seen.peaks) {
    if (!coherent(pk) || pk.magnitude < kClearFraction * largest || explained(pk, out.modes) ||
        explained(pk, out.dropped))
      continue;
    const double prom = prominence(pk);
    if (pk.lines_in_band < kMinLines && prom < kProminent && pk.magnitude < band_largest) continue;
    if (!ClearOfNoise(receptance, options.picking_column, pk, prom)) continue;
    named.emplace_back(prom, &pk);
  }
  std::stable_sort(named.begin(), named.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  out.peaks_without_mode_hz.clear();
  out.peaks_without_mode_zeta.clear();
  for (const auto& [prom, peak] : named) {
    const Peak& pk = *peak;
    out.peaks_without_mode_hz.push_back(pk.freq_hz);
    out.peaks_without_mode_zeta.push_back(pk.zeta);
    std::string way;
    switch (options.method) {
      case ModeMethod::kLscf:
      case ModeMethod::kLsce:
        way = "raise the orders (--orders" +
              (out.has_diagram && !out.diagram.orders.empty()
                   ? ", now " + std::to_string(out.diagram.orders.front()) + ":" +
                         std::to_string(out.diagram.orders.back())
                   : std::string()) +
              "), give a band around it (--fmin-hz/--fmax-hz), or use --method fit";
        break;
      default:
        way =
            "give a band around it (--fmin-hz/--fmax-hz), lower --threshold, or use --method "
            "lscf";
        break;
    }
    if (options.peaks.max_peaks > 0)
      way += "; --max-modes " + std::to_string(options.peaks.max_peaks) + " may have left it out";
    char line[160];
    std::snprintf(line, sizeof line,
                  "a clear peak at %.5g Hz in the band has no mode: ", pk.freq_hz);
    // The fallback chain identifies again through IdentifyModes: one warning per peak.
    const std::string warning = line + way;
    if (std::find(out.warnings.begin(), out.warnings.end(), warning) == out.warnings.end())
      out.warnings.push_back(warning);
  }
}

}  // namespace

ModeIdentification IdentifyModes(const Frf& receptance, std::size_t driving_point,
                                 const ModeIdentificationOptions& options) {
  Require(receptance.quantity == Quantity::kDisplacement,
          "mode identification needs a receptance FRF");
  Require(driving_point < receptance.responses(), "driving-point response out of range");
  ModeIdentification out =
      options.method == ModeMethod::kLscf || options.method == ModeMethod::kLsce
          ? IdentifyFromDiagram(receptance, driving_point, options)
          : IdentifyFromPeaks(receptance, driving_point, options);
  DropUnresolvedModes(out);
  NameWindowDampingOverOwn(receptance.exp_window_tau_s, out);
  NamePeaksWithoutMode(receptance, options, out);
  return out;
}

}  // namespace vibid::ident
