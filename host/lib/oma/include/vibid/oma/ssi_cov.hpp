// Output-only (operational) modal analysis: covariance-driven stochastic subspace identification
// (methods §13; Peeters & De Roeck, MSSP 13(6) 1999), a stabilization diagram over model orders,
// automatic pole choice by clustering (Magalhães, Cunha & Caetano, MSSP 23(2) 2009) and 95 %
// intervals from the covariance of the Hankel matrix over data blocks (Reynders, Pintelon &
// De Roeck, MSSP 22(4) 2008), propagated to ω, ζ and the shapes by sampling that covariance.
//
// The responses alone: no force is measured. The rig runs under broadband ambient or operating
// excitation that is roughly white over the band analysed.
#pragma once

#include <complex>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace vibid::oma {

/// Every default is chosen from the data and the band, so nothing needs tuning for a rig whose
/// modes lie in [fmin_hz, fmax_hz]. Options are validated up front (InputError naming the option).
struct SsiCovOptions {
  double fs_hz = 0.0;    ///< Sample rate of the responses (> 0, required).
  double fmax_hz = 0.0;  ///< Top of the band analysed; 0: fs/2.5. The data are low-passed and
                         ///< decimated to about 2.5 fmax (anti-aliased), which keeps the Hankel
                         ///< matrix small and its lags long enough to resolve the lowest modes.
  double fmin_hz = 0.0;  ///< Lowest mode of interest; 0: fmax/10. Sets the lags (below).
  int block_rows = 0;    ///< Block rows i of the Hankel matrix (2i lags); 0: the lags span a
                         ///< period of fmin, at least order_max / channels + 2 rows, at most 100.
  int order_max = 0;     ///< Largest model order (even); 0: min(40, i · channels).
  /// Soft stability criteria between consecutive orders: relative frequency change, relative
  /// damping change, 1 − MAC. Frequency and shape take the usual defaults of the SSI literature
  /// (1 %, 2 %); damping is the least precise of the three (10 to 20 % relative scatter on a
  /// five-minute record), and the literature's 5 % breaks a real mode's chain of poles there,
  /// so it is 20 %.
  double stable_freq_tol = 0.01;
  double stable_damping_tol = 0.2;
  double stable_mac_tol = 0.02;
  double max_damping = 0.2;  ///< Hard criterion: poles with ζ ≤ 0 or above this are not physical.
  /// A cluster of stable poles (at least 5) is a mode when it holds poles from at least this
  /// share of the orders that could carry it: those from its lowest order up.
  double min_cluster_share = 0.5;
  /// A cluster whose 95 % frequency half-width exceeds this share of its frequency (an interval
  /// spanning more than 6 % at the default) is not reported as a mode: a real mode of a record
  /// long enough for SSI-cov is known to well under 1 %, while noise poles that lined up scatter
  /// over several percent (± 6 % seen at 16 Hz on a 2-mass rig whose spectrum has nothing there).
  double max_omega_ci95_share = 0.03;
  int blocks = 20;  ///< Data blocks for the Hankel covariance (≥ 6); the interval uses Student's
                    ///< t with blocks − 1 degrees of freedom.
  int draws = 200;  ///< Samples of the Hankel covariance propagated to the modes (≥ 50).
  unsigned seed = 1;  ///< Seed of those samples (the result is reproducible).

  void Validate() const;
};

/// One pole of the stabilization diagram.
struct Pole {
  int order = 0;
  double omega_rad_s = 0.0;
  double zeta = 0.0;
  bool stable = false;  ///< Meets the soft criteria against a pole of the order below.
  int cluster = -1;     ///< Index into SsiCovResult::modes, or −1.
};

struct OmaMode {
  double omega_rad_s = 0.0;
  double zeta = 0.0;
  Eigen::VectorXd shape;  ///< Real-normalised (largest entry +1), one entry per channel.
  /// 95 % half-widths (t quantile × standard deviation over the Hankel covariance samples).
  double omega_ci95_rad_s = 0.0;
  double zeta_ci95 = 0.0;
  Eigen::VectorXd shape_ci95;
  double mpc = 0.0;      ///< Modal phase collinearity of the complex shape (1: a real mode).
  int order = 0;         ///< Model order the values come from (the cluster's median pole).
  int cluster_size = 0;  ///< Stable poles in the cluster.
  /// Share of the covariance samples in which the mode was found again (at least 0.9: a cluster
  /// found again less often is not reported as a mode; SsiCovResult::message names it).
  double found_share = 0.0;
};

struct SsiCovResult {
  std::vector<OmaMode> modes;  ///< Ascending in frequency.
  std::vector<Pole> diagram;   ///< Every physical pole of every order.
  double fs_hz = 0.0;          ///< Sample rate analysed (after decimation).
  int decimation = 1;
  int block_rows = 0;
  int order_max = 0;
  int channels = 0;
  long samples = 0;                     ///< Samples analysed (after decimation).
  std::vector<double> singular_values;  ///< Of the Hankel matrix (the order's evidence).
  std::string message;                  ///< Empty, or why no mode or no interval could be given.
};

/// Output covariances R_k = 1/(N−k) Σ y_{t+k} y_tᵀ for k = 0 … lags (mean removed first), one
/// l×l matrix per lag, stacked horizontally: l × l(lags+1).
Eigen::MatrixXd OutputCovariances(Eigen::Ref<const Eigen::MatrixXd> y, int lags);

/// Low-pass (windowed-sinc FIR, zero phase) and keep every `factor`-th sample. factor 1: copy.
Eigen::MatrixXd Decimate(Eigen::Ref<const Eigen::MatrixXd> y, int factor);

/// SSI-cov of the responses `y` (one row per sample, one column per channel; at least 1 channel).
/// InputError for bad options or data too short for the Hankel matrix and blocks.
SsiCovResult SsiCov(Eigen::Ref<const Eigen::MatrixXd> y, const SsiCovOptions& options);

/// Modal assurance criterion of two complex shapes, in [0, 1].
double Mac(const Eigen::VectorXcd& a, const Eigen::VectorXcd& b);

}  // namespace vibid::oma
