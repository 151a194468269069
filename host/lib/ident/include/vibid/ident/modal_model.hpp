// The modal model behind the stabilization diagram's poles, and its uncertainty: a maximum-
// likelihood fit of the pole-residue model to the FRF, started from the chosen poles ("ML-MM",
// El-kafafy, Guillaume, Peeters, "Modal parameter estimation by combining stochastic and
// deterministic frequency-domain approaches", MSSP 35 (2013) 52-68; the covariance as in
// Pintelon, Guillaume, Schoukens, "Uncertainty calculation in (operational) modal analysis",
// MSSP 21 (2007) 2359-2373).
//
//   H_a(w) = sum_i [ R_i / (jw - lambda_i) + conj(R_i) / (jw - conj(lambda_i)) ] + c - w^2 d
//
// (with a pretrigger t_p, plus exp(j w t_p) sum_i [ S_i / (jw - lambda_i) + conj(S_i) / (...) ],
// see below) on the accelerance (residuals: c for the modes below the band and the accelerometer's
// direct term, d for the modes above it), each response with its own complex residues R_i, every
// line weighted by the inverse of its standard deviation. Why this form and not the modal form A /
// (w_i^2 - w^2 + 2j zeta w_i w) with a complex A: a record that ends before the response has died
// out (or that starts in the previous hit's ringing) multiplies each mode's residue at the DFT
// lines by one complex factor 1 - exp(lambda T), the same for every response. The pole-residue form
// carries that factor exactly, so shape ratios stay unbiased; the modal form with a complex A puts
// the factor's imaginary part on j instead of j w and pushes the misfit into the damping and the
// shapes. When the hit sits t_p into its record, H1 = X / F divides by the force's exp(-j w t_p):
// the response to the hit keeps the plain pole terms, while the ringing cut off at the record's end
// and the previous hits' tails (free decays present from the record's start) come with exp(j w t_p)
// - the S_i terms. Without them the misfit of a decay that spans one line or two biases zeta by 1-2
// % (synthetic 2-DOF, 16 s records, zeta 0.7 %).
//
// Noise: white in each response's accelerance over the band (an accelerometer's noise floor over
// a hammer's flat force spectrum), its level from the fit's residuals with the degrees of freedom
// the fit used. Why not the variance the hits' coherence implies, |H|^2 (1 - coh) / (coh (n - 1))
// (Bendat & Piersol, Random Data, §9.2.3): the coherence also drops where the previous hits'
// ringing differs from hit to hit, which the model's S_i terms explain; on the synthetic 2-DOF
// test it overstated the standard deviation of zeta fourfold at the resonances.
//
// Why this and not the scatter of the poles over the diagram's orders: the order-to-order spread
// measures how the polynomial model settles, not how the data vary; it shrinks with the number of
// orders and says nothing about the noise. The covariance of the likelihood fit is the Cramér-Rao
// bound of the modal parameters under the stated noise model, and the refined poles are the
// estimator it belongs to, so the intervals cover the truth at their stated rate (checked over
// seeded synthetic hammer tests).
#pragma once

#include <Eigen/Core>
#include <array>
#include <complex>
#include <string>
#include <vector>

#include "vibid/ident/spectral.hpp"
#include "vibid/numerics/least_squares.hpp"

namespace vibid::ident {

/// Two-sided 95 % normal quantile.
inline constexpr double kZ95 = 1.959963984540054;

/// value +- kZ95 sd; both NaN unless sd is finite and > 0 (an interval of width 0 is never an
/// estimate: it is a variance that could not be computed).
std::array<double, 2> ModalInterval95(double value, double sd);

struct ModalModelOptions {
  /// Fitted band (Hz); 0: from 0.6x the lowest to 1.4x the highest start pole, within the data.
  double freq_min_hz = 0.0;
  double freq_max_hz = 0.0;
  /// Refine the poles (Gauss-Newton on poles and residues) up to this many iterations; 0 keeps
  /// the start poles and fits the residues only (the covariance is then that of the start poles
  /// if they were the minimum).
  int max_iterations = 30;
  /// Bands with more lines than this keep only the lines near the poles (see FitModalModel).
  int max_lines = 4000;

  /// InputError naming the first bad field.
  void Validate() const;
};

struct ModalModelFit {
  /// Poles as the FRF shows them (an exponential window's damping included), ordered as given.
  Eigen::VectorXcd lambda;
  /// Accelerance residues at the resonance, poles x responses: R_i + S_i exp(j omega_d t_p) (both
  /// are proportional to the shape of a real mode; their sum is what the peak shows).
  Eigen::MatrixXcd residues;
  double pretrigger_s = 0.0;
  /// Natural frequency and damping ratio per pole, corrected for the FRF's exponential window.
  Eigen::VectorXd omega_rad_s;
  Eigen::VectorXd zeta;
  /// Standard deviations of omega and zeta (window-corrected); NaN where the data do not
  /// determine them (see `undetermined`), never 0.
  Eigen::VectorXd omega_sd_rad_s;
  Eigen::VectorXd zeta_sd;
  /// Covariance of [omega_i, zeta_i (as the FRF shows them) for every pole, then per response
  /// Re R_i, Im R_i for every pole, (with a pretrigger) the ringing term's Re S_i, Im S_i, c, d].
  Eigen::MatrixXd covariance;
  Eigen::Index per_response = 0;  ///< Parameters per response in `covariance`.
  /// Parameter directions (columns, in the parameters of `covariance`) that the band's lines do
  /// not determine: the information matrix is numerically singular along them. `covariance` is
  /// its pseudo-inverse on the other directions; a quantity that moves along these has no
  /// variance (Variance gives NaN).
  Eigen::MatrixXd undetermined;
  /// The least variance a unit step along an undetermined direction can have.
  double undetermined_variance = 0.0;
  /// Smallest over largest eigenvalue of the column-scaled information matrix.
  double min_eigenvalue_ratio = 0.0;
  /// The pretrigger's ringing terms S_i are in the model (false: no pretrigger, or the lines
  /// could not tell them from the hit's own residues and they were left out; see `note`).
  bool ringing_terms = false;
  /// The record has a pretrigger but its ringing terms were left out (see FitModalModel): the
  /// previous hits' ringing the records hold is then neither modelled nor in the noise level,
  /// so the covariance understates the uncertainty (a1/a2 off by about 1 % against intervals of
  /// that size on 1 s records) and gives no interval.
  bool ringing_terms_dropped = false;
  std::string note;
  double freq_min_hz = 0.0;
  double freq_max_hz = 0.0;
  int lines = 0;
  /// Weighted misfit per degree of freedom with the noise levels from the residuals (about 1; the
  /// covariance is scaled by it).
  double reduced_chi2 = 0.0;
  numerics::SolverSummary summary;

  /// Projection of response j's residue on response p's, Re(R_j conj(R_p)) / |R_p|^2 (the shape
  /// ratio phi_j / phi_p of a real mode), and its standard deviation.
  double ShapeRatio(Eigen::Index mode, Eigen::Index j, Eigen::Index p) const;
  double ShapeRatioSd(Eigen::Index mode, Eigen::Index j, Eigen::Index p) const;
  /// Variance of the linearised quantity with this gradient in the parameters of `covariance`;
  /// NaN when the data do not determine it or the variance is not positive.
  double Variance(const Eigen::VectorXd& gradient) const;
};

/// Fits the model above to a receptance (converted to accelerance) with the given start poles
/// (lambda = -zeta omega + j omega sqrt(1 - zeta^2) as the FRF shows them, i.e. before any
/// exponential-window correction). InputError for a non-receptance, no start pole, or too few
/// usable lines in the band. When the band's lines leave the ringing terms undetermined (short
/// records: the pretrigger's phase exp(j w t_p) hardly turns over the band) the model is fitted
/// again without them and that fit is kept if it determines every parameter and its poles stay
/// within 1 % (omega) and 50 % (zeta) of the first fit's.
ModalModelFit FitModalModel(const Frf& receptance, const std::vector<std::complex<double>>& start,
                            const ModalModelOptions& options);

}  // namespace vibid::ident
