// Pole estimation over a range of model orders and the stabilization diagram (methods §5, "a
// best-in-class tool also offers ... least-squares complex-frequency methods with a
// stabilisation diagram"):
//
//  - pLSCF ("PolyMAX", Peeters, Van der Auweraer, Guillaume, Leuridan, Shock and Vibration 11
//    (2004) 395-409; Guillaume et al., IMAC XXI, 2003): a common-denominator rational model in
//    the z-domain, H_o(w) = B_o(W) / A(W) with W = exp(j w dt), dt = 1 / (2 f_hi), fitted by linear
//    least squares on the reduced normal equations M = 2 sum_o (T_o - S_o^T R_o^-1 S_o) with the
//    highest denominator coefficient fixed to 1. One force (single reference), every response.
//    With the default band (all lines to the Nyquist line of a per-hit FRF) dt is the sample
//    period, and the model is exact for records that end before the response has died out: the
//    DFT of a truncated sum of exponentials is a rational function of W with the same poles, so
//    the short-record leakage that biases half-power and modal curve fits does not bias these
//    poles.
//  - LSCE (least-squares complex exponential, Brown et al., SAE 790221, 1979): the impulse
//    responses (inverse FFT of the accelerance over the whole band) obey one linear recursion
//    of order n for every response; its characteristic roots are the poles.
//
// Each order gives poles lambda = ln(z) / dt; a pole is stable in frequency, damping and shape
// when the nearest pole of the previous order lies within the tolerances. Physical poles are
// chosen automatically: the fully stable poles are clustered in frequency, and a cluster that
// appears at enough orders is a mode (its median frequency and damping).
#pragma once

#include <complex>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "vibid/ident/spectral.hpp"

namespace vibid::ident {

enum class PoleMethod { kLscf, kLsce };
const char* PoleMethodName(PoleMethod method);

struct StabilizationOptions {
  PoleMethod method = PoleMethod::kLscf;
  /// Band of the pLSCF fit and of the poles kept (Hz). 0: from the first line above 0 / to the
  /// last line.
  double freq_min_hz = 0.0;
  double freq_max_hz = 0.0;
  /// Model orders (number of poles, conjugates included) min, min + step, ..., max. max 0: from
  /// the band's lines (AutomaticMaxOrder).
  int min_order = 4;
  int max_order = 0;
  int order_step = 2;
  /// Stability against the previous order: relative frequency change, relative damping change,
  /// and the modal assurance criterion of the shapes.
  double freq_tolerance = 0.01;
  double damping_tolerance = 0.05;
  double mac_min = 0.98;
  /// Poles with a damping ratio outside (min, max) are not modes (unresolved, or numerical).
  double min_zeta = 1e-5;
  double max_zeta = 0.3;
  /// A cluster of fully stable poles is chosen when it holds poles of at least this fraction of
  /// the orders (and of at least 3 orders).
  double min_cluster_fraction = 0.3;

  /// InputError naming the first bad field.
  void Validate() const;
};

/// "MIN:MAX" or "MIN:MAX:STEP" into the options' orders; InputError otherwise.
void ParseOrders(std::string_view text, StabilizationOptions& options);

/// The highest order a band of `lines` frequency lines carries when the options leave it open:
/// a quarter of the lines, or up to min + 6 step when half the lines (pLSCF; a quarter for LSCE,
/// whose impulse-response rows shrink as the order grows) allow it, at most 48, on the grid
/// min, min + step, ...; 0 when that is below min + 3 step, the
/// fewest orders a mode can be chosen from (a pole is stable only against the previous order,
/// and a mode needs stable poles at 3 orders).
int AutomaticMaxOrder(int lines, const StabilizationOptions& options);

/// The lines a band needs for the options' orders: for the highest order given, or for the
/// fewest automatic orders (min + 3 step) when it is left open.
int LinesNeeded(const StabilizationOptions& options);

struct DiagramPole {
  int order = 0;
  double freq_hz = 0.0;
  double zeta = 0.0;
  bool stable_freq = false;
  bool stable_damping = false;
  bool stable_shape = false;
  int cluster = -1;  ///< Index into StabilizationDiagram::selected when the pole is part of one.
  /// pLSCF: the numerators B_o at the pole, one per response (proportional to the residues, so
  /// their ratios are the mode shape). LSCE: empty.
  Eigen::VectorXcd shape;
  bool Stable() const { return stable_freq && stable_damping && stable_shape; }
};

struct SelectedPole {
  double omega_rad_s = 0.0;  ///< Undamped natural frequency |lambda|.
  double freq_hz = 0.0;
  double zeta = 0.0;
  int orders = 0;            ///< Orders at which the cluster's pole appears.
  double freq_spread = 0.0;  ///< Relative standard deviation of the members' frequencies.
  double zeta_spread = 0.0;  ///< Relative standard deviation of the members' damping.
};

struct StabilizationDiagram {
  PoleMethod method = PoleMethod::kLscf;
  double freq_min_hz = 0.0;  ///< Band used.
  double freq_max_hz = 0.0;
  std::vector<int> orders;
  std::vector<DiagramPole> poles;      ///< Every physical-looking pole of every order, in the band.
  std::vector<SelectedPole> selected;  ///< Chosen poles, in frequency order.
};

/// Every root of the pLSCF denominator of `order` fitted over [freq_min_hz, freq_max_hz] (0: as in
/// StabilizationOptions) as continuous-time poles lambda = ln(z) / dt, dt = 1 / (2 f_hi), and the
/// numerators B_o evaluated at each root (responses x poles; proportional to the residues, so
/// their ratios are the mode shape). Weights: sqrt(coherence) / max |H_o| over the band (the
/// paper's unity weighting, each response scaled to its largest value). The FRF is fitted as given.
struct PoleSet {
  Eigen::VectorXcd lambda;
  Eigen::MatrixXcd shapes;
};
PoleSet LscfPoles(const Frf& frf, double freq_min_hz, double freq_max_hz, int order);

/// LSCE poles of `order` from the impulse responses of the accelerance (the FRF converted) over the
/// lines up to `freq_max_hz` (0: the last line), which become the Nyquist line of the impulse
/// responses (dt = 1 / (2 f_max)); every line from the first up to it is needed, a missing DC
/// line is taken as 0.
PoleSet LscePoles(const Frf& frf, int order, double freq_max_hz = 0.0);

/// Poles over the orders, stability flags and the automatic choice of the physical poles; orders
/// left open (max_order 0) come from the band's lines (AutomaticMaxOrder). InputError naming the
/// band, its lines and the way out when the band holds too few lines for the orders. pLSCF
/// fits the FRF converted to accelerance (what accelerometers measure: a truncated record's DFT
/// ratio is then rational in W, and resonances decades apart weigh alike). Damping is corrected
/// for the FRF's exponential window.
StabilizationDiagram BuildStabilizationDiagram(const Frf& frf, const StabilizationOptions& options);

/// Bands for resonances spread over decades: a pole near DC of a band that reaches far above it
/// sits where z = exp(lambda dt) crowds 1 and is lost to the polynomial's conditioning. The
/// resonances (sorted, Hz) are grouped so that each group spans at most a factor `max_span`; each
/// group gets the band [0.6 f_first (0 for the first group), min(last_line, 1.6 f_last)].
std::vector<std::pair<double, double>> AutomaticBands(std::vector<double> resonances_hz,
                                                      double last_line_hz, double max_span = 8.0);

/// One diagram per band (options' band ignored), merged: chosen poles of overlapping bands within
/// the frequency tolerance of each other count once (the one seen at more orders). A band with
/// fewer lines than LinesNeeded is widened upwards to hold them (up to the last line).
StabilizationDiagram BuildStabilizationDiagram(const Frf& frf, const StabilizationOptions& options,
                                               const std::vector<std::pair<double, double>>& bands);

}  // namespace vibid::ident
