// Spectral estimation: windows, Welch-averaged auto/cross spectra, FRF estimators (methods §4).
//
// Conventions (the same as scipy.signal.csd/welch, so results can be checked against it):
//  - one-sided spectra, density scaling: G = 2 X^* Y / (fs sum w^2), DC (and Nyquist for even
//    segments) not doubled; units (signal unit)^2 / Hz;
//  - G_fx = E[F^* X] (force conjugated), so H1 = G_fx / G_ff;
//  - windows are periodic ("DFT-even"), as scipy.signal.get_window returns by default.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <string_view>
#include <span>
#include <vector>

#include <Eigen/Core>

namespace vibid::ident {

enum class Window { kRectangular, kHann, kHamming, kBlackmanHarris, kFlatTop };
/// "rect"|"boxcar", "hann", "hamming", "blackmanharris", "flattop"; InputError otherwise.
Window ParseWindow(std::string_view name);
const char* WindowName(Window window);
/// Periodic window of n samples.
Eigen::VectorXd MakeWindow(Window window, std::size_t n);

enum class Detrend { kNone, kConstant };

enum class Estimator { kH1, kH2, kHv };
/// "h1", "h2", "hv"; InputError otherwise.
Estimator ParseEstimator(std::string_view name);
const char* EstimatorName(Estimator estimator);

/// What the FRF's numerator is: displacement (receptance), velocity (mobility) or acceleration
/// (accelerance). Also names a sensor type.
enum class Quantity { kDisplacement, kVelocity, kAcceleration };
/// "disp"|"receptance", "vel"|"mobility", "acc"|"accelerance"; InputError otherwise.
Quantity ParseQuantity(std::string_view name);
/// "receptance", "mobility", "accelerance".
const char* FrfKindName(Quantity quantity);

struct WelchOptions {
  std::size_t segment_samples = 1024;
  std::size_t overlap_samples = 512;
  Window window = Window::kHann;
  Detrend detrend = Detrend::kNone;
  /// Threads that transform segments (0: one per core). The segments are summed in eight fixed runs
  /// whatever the count, so the spectra are the same to the last bit for any value.
  std::size_t threads = 0;
  /// InputError when the record is too short for one segment or overlap >= segment.
  void Validate(std::size_t record_samples) const;
};

/// Averaged one-sided spectra of one input (force) and several outputs (responses).
struct CrossSpectra {
  Eigen::VectorXd freq_hz;  ///< Lines 0 .. fs/2, spacing fs/segment.
  Eigen::VectorXd gff;      ///< Force auto-spectrum.
  Eigen::MatrixXd gxx;      ///< lines x responses, response auto-spectra.
  Eigen::MatrixXcd gfx;     ///< lines x responses, E[F^* X].
  std::size_t averages = 0;
};

/// Welch averaging over segments. `responses` has one column per response channel. Segments are
/// transformed on `options.threads` threads, each with its own FFT plan and buffers.
CrossSpectra WelchSpectra(const Eigen::Ref<const Eigen::VectorXd>& force,
                          const Eigen::Ref<const Eigen::MatrixXd>& responses, double fs_hz,
                          const WelchOptions& options);
/// The same from separate response channels (e.g. a recording's own columns, read in place).
CrossSpectra WelchSpectra(const Eigen::Ref<const Eigen::VectorXd>& force,
                          std::span<const Eigen::VectorXd* const> responses, double fs_hz,
                          const WelchOptions& options);

/// Estimated FRFs of several responses to one force, with coherence.
struct Frf {
  Eigen::VectorXd freq_hz;    ///< Uniform lines (the DC line may be absent after a conversion).
  Eigen::MatrixXcd h;         ///< lines x responses.
  Eigen::MatrixXd coherence;  ///< lines x responses, ordinary coherence in [0, 1].
  Quantity quantity = Quantity::kDisplacement;
  Estimator estimator = Estimator::kH1;
  std::size_t averages = 0;
  /// Time constant of an exponential response window (s); 0 when none. Identified damping must be
  /// corrected by -1/(tau omega) (see CorrectExponentialWindowDamping).
  double exp_window_tau_s = 0.0;
  /// Impact FRFs: time from the start of each hit's record to the trigger (s); 0 otherwise. The
  /// ringing a record holds beyond its own hit's response (the record's end cutting the decay, the
  /// previous hit's tail) enters H1 multiplied by exp(j omega pretrigger_s); modal_model.hpp.
  double pretrigger_s = 0.0;
  /// Impact FRFs: length of each hit's record (s), 0 otherwise. The record's end cuts each hit's
  /// (windowed) decay there, which a fit of the FRF's level must model (updates.cpp).
  double record_s = 0.0;
  /// What the response channels measured (the FRF may have been converted since): the record's
  /// end cuts the decay of that quantity, and an exponential window multiplies it.
  Quantity measured = Quantity::kDisplacement;
  /// Impact FRFs: per line, the variance of the relative error of |H| that the force noise inside
  /// the force windows causes. It is the same on neighbouring lines (a window of a few samples has
  /// a flat spectrum), so it scales a resonance as a whole and no fit's residuals show it. Empty
  /// when not known (Welch FRFs, FRF files).
  Eigen::VectorXd level_rel_var;
  /// Impact FRFs: the band where the hammer's force excites the structure (Hz), from the first
  /// line to the last before the force spectrum first falls ImpactOptions::force_excited_db below
  /// its largest value. Above it H1 is the record's noise over a vanishing force (the pulse's
  /// notch): mode identification analyses, and names peaks without a mode, only inside it unless
  /// a band is given. Both 0 when not known (Welch FRFs, FRF files without it): every line.
  double force_band_min_hz = 0.0;
  double force_band_max_hz = 0.0;
  std::vector<std::string> response_names;
  std::string force_name;

  std::size_t lines() const { return static_cast<std::size_t>(freq_hz.size()); }
  std::size_t responses() const { return static_cast<std::size_t>(h.cols()); }
};

/// H1 = Gfx/Gff, H2 = Gxx/Gxf, Hv = total least squares with equal noise weights on both channels:
/// (Gxx - Gff + sqrt((Gxx - Gff)^2 + 4|Gfx|^2)) / (2 Gxf). Coherence |Gfx|^2 / (Gff Gxx).
/// Lines where the force spectrum vanishes get H = 0 and coherence 0.
Frf FrfFromSpectra(const CrossSpectra& spectra, Estimator estimator, Quantity response_quantity);

/// Converts between receptance, mobility and accelerance by powers of j*omega. Dividing drops the
/// DC line (the conversion is undefined there).
Frf ConvertFrf(const Frf& frf, Quantity target);

/// Damping ratio with the damping that an exponential window exp(-t/tau) adds removed:
/// the window multiplies each mode's decay exp(-zeta omega t) by exp(-t/tau), which moves the
/// pole's real part by 1/tau and leaves the damped frequency as it is.
double CorrectExponentialWindowDamping(double zeta_measured, double omega_rad_s, double tau_s);

/// Reusable real FFT plan (kissfft<double>); half-spectrum of n real samples, lines 0..n/2.
class RealFft {
 public:
  explicit RealFft(std::size_t n);
  ~RealFft();
  RealFft(const RealFft&) = delete;
  RealFft& operator=(const RealFft&) = delete;
  std::size_t size() const { return n_; }
  /// `out` is resized to n/2 + 1.
  void Transform(const double* in, Eigen::VectorXcd& out);

 private:
  struct Plan;
  std::size_t n_;
  std::unique_ptr<Plan> plan_;
};

}  // namespace vibid::ident
