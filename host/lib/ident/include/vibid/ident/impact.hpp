// Impact (hammer) testing: hit detection, per-hit records with force and exponential windows,
// double-hit and clipping checks, and the FRF averaged over the good hits (methods §4).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "vibid/ident/spectral.hpp"

namespace vibid::ident {

struct ImpactOptions {
  /// A pulse is where |force - baseline| exceeds this fraction of the largest such value.
  double trigger_fraction = 0.1;
  /// Samples kept before each trigger (s). Negative: automatic, 1/64 of the hit record, limited
  /// to what precedes the first hit.
  double pretrigger_s = -1.0;
  /// Length of each hit's record (s). 0: automatic, the shortest spacing between hits (or what is
  /// left after a single hit), rounded down to a fast FFT length.
  double record_s = 0.0;
  /// Force window: force kept from the record start to this time after the trigger (s), then a
  /// half-cosine taper of the same length as the pulse. 0: automatic, twice the pulse width.
  double force_window_s = 0.0;
  /// Exponential window on force and responses, starting at the trigger: its value at the record
  /// end. 0: no exponential window. (tau = T / ln(1 / end_value).)
  double exp_window_end = 0.0;
  /// Pulses closer than this to the previous pulse (s) belong to the same hit (a rebound).
  double double_hit_window_s = 0.05;
  /// A later pulse in a hit's record counts as a double hit when its peak exceeds this fraction of
  /// the hit's peak.
  double double_hit_fraction = 0.05;
  /// A channel is clipped when at least this many consecutive samples sit on (or beyond) its
  /// converter's limit: by default one, a single sample at the rail has lost its true value.
  std::size_t clip_run_samples = 1;
  /// The converter's limits per channel, in the channel's units: the force first, then one per
  /// response (a recording's sidecar states them). A channel with limits is clipped only where it
  /// sits on one of them (a 12-bit converter's codes 0 and 4095), never on a top code it merely
  /// repeats inside its range. Empty, or an entry with lo >= hi: the limits are unknown, the
  /// channel is not checked, and a warning says the clip check is unavailable for it.
  struct ConverterLimits {
    double lo = 0.0;
    double hi = 0.0;
    bool Known() const { return lo < hi; }
  };
  std::vector<ConverterLimits> converter_limits;
  /// Reject double hits and clipped hits (true) or only flag them (false). When every hit that
  /// is not truncated is a double hit (and none is clipped), they are used all the same, with a
  /// warning: a record of double hits still holds an FRF where the force has energy.
  bool reject_bad_hits = true;
  /// With double hits in the average, lines where the force auto-spectrum is more than this far
  /// below its largest value (dB) carry no FRF: the rebound cancels the first pulse near
  /// multiples of 1/delay, and H1 there is noise over a vanishing force. The usable band runs
  /// from the first line to the first line that falls short; above it the coherence is set to 0.
  double force_dynamic_range_db = 20.0;
  /// Without double hits: lines above the first where the force auto-spectrum falls more than
  /// this far below its largest value (dB) carry no FRF either (coherence 0): above the hammer's
  /// band, at its pulse's first notch, H1 is the hits' other content over a vanishing force. 0:
  /// every line.
  double force_band_db = 30.0;
  /// The band where the force excites the structure (Frf::force_band_min_hz/max_hz): up to the
  /// last line before the force auto-spectrum first falls this far below its largest value (dB).
  /// The usual rule for a hammer's useful range is a force spectrum within 10-20 dB of its level
  /// (Ewins, Modal Testing, 2nd ed., ch. 3); 20 dB keeps the LADISK beam's mode at 5975 Hz, where
  /// its hammer's force is 15.7 dB down and the mode is well determined. A 2 ms half-sine falls
  /// 20 dB by 650 Hz and has its first notch at 750 Hz. 0: the usable band (force_band_db).
  double force_excited_db = 20.0;
  /// A response line above the force's 10 dB point carries no FRF (coherence 0) where its
  /// auto-spectrum is below this multiple of its converter's rounding noise (the channel's
  /// smallest step q, variance q^2 / 12, white):
  /// with a single hit every coherence is 1, and an encoder's count of 1e-5 m turned into H,
  /// where the displacement is below one count, gave hundreds of noise "peaks" at 650-730 Hz.
  /// 0: no such check.
  double response_resolution_factor = 10.0;
  /// A hit is too weak when its peak is below this fraction of the median peak of the complete,
  /// single, unclipped hits: a tap that light drives the structure less far into its nonlinearity
  /// than the others and lifts its response less far above the noise. 0: no such check.
  double weak_hit_fraction = 0.3;
  /// ... or when its peak is below this many standard deviations of the force channel's noise
  /// (median absolute deviation of the whole force). 0: no such check.
  double weak_hit_noise_factor = 10.0;
  /// A hit whose responses at the record's end still ring at this fraction of their level just
  /// after the hit is flagged (Hit::ringing). 0: no such check.
  double ringing_fraction = 0.1;
  /// The hits to average, 1-based in the order they are detected; empty: the verdicts decide.
  /// A listed hit is used whatever its verdict (the operator's choice), except a truncated one,
  /// which is refused: its record does not fit in the recording.
  std::vector<std::size_t> use_hits;

  void Validate() const;
};

struct Hit {
  std::size_t trigger_index = 0;  ///< First sample above the trigger level.
  std::size_t peak_index = 0;
  double t_s = 0.0;     ///< Trigger time from the record start.
  double peak_n = 0.0;  ///< Peak force above the baseline (force units).
  double pulse_width_s = 0.0;
  bool double_hit = false;
  bool clipped = false;
  bool truncated = false;  ///< The record ends before the hit's window does.
  bool weak = false;       ///< Peak too low: see ImpactOptions::weak_hit_fraction.
  /// The responses still ring at the end of the hit's record: the largest response's RMS over the
  /// record's last eighth is at least `ringing_fraction` of its RMS over the first eighth after
  /// the trigger (see ImpactOptions::ringing_fraction), times the exponential window's end value
  /// when there is one. The hit is used: the pole-residue model
  /// carries the cut-off ringing, but peak picking and the curve fit see it as leakage.
  bool ringing = false;
  double ringing_ratio = 0.0;  ///< That RMS ratio for the response that rings most.
  /// That response's amplitude decay rate over the record's late part (1/s; from its RMS over the
  /// last two eighths, before any exponential window), the own decay of the mode that rings
  /// longest; 0 where it does not decay measurably or is not checked.
  double ringing_decay_1_s = 0.0;
  std::size_t pulses =
      1;  ///< Pulses of this hit (a rebound within the double-hit window adds one).
  bool used = false;
  std::string note;  ///< Why a hit was rejected or flagged; empty when clean.
};

/// Where one hit's record lies and how its force window runs (samples).
struct HitSpan {
  std::size_t start = 0;  ///< First sample of the hit's record.
  std::size_t keep = 0;   ///< Force kept from the record start before the taper.
  std::size_t taper = 0;  ///< Length of the half-cosine taper: the hit's first pulse's width.
};

struct ImpactResult {
  Frf frf;
  std::vector<Hit> hits;
  std::vector<HitSpan> spans;  ///< One per hit (see ImpactDetection).
  std::size_t record_samples = 0;
  std::size_t pretrigger_samples = 0;
  /// Band where the FRF is usable (Hz): up to where the force spectrum leaves its dynamic range
  /// (ImpactOptions::force_band_db; force_dynamic_range_db with double hits).
  double usable_min_hz = 0.0;
  double usable_max_hz = 0.0;
  /// Where the force excites the structure (ImpactOptions::force_excited_db), within the usable
  /// band; the FRF carries it (Frf::force_band_min_hz/max_hz).
  double excited_max_hz = 0.0;
  std::vector<std::string> warnings;
};

/// The hits of a record as EstimateImpactFrf detects and judges them, and what their spectra are
/// computed from. `hits[i].used` holds the verdict, or the choice of ImpactOptions::use_hits.
struct ImpactDetection {
  std::vector<Hit> hits;
  std::vector<HitSpan> spans;  ///< One per hit.
  std::size_t record_samples = 0;
  std::size_t pretrigger_samples = 0;
  double baseline = 0.0;         ///< Median of the force.
  double trigger_level = 0.0;    ///< |force - baseline| where a pulse starts.
  double force_noise_var = 0.0;  ///< Variance of the force channel's noise.
  /// Per response, the variance of its rounding noise: q^2 / 12 for the smallest step q between
  /// consecutive samples (a converter's code, an encoder's count; tiny for data in floating
  /// point).
  std::vector<double> response_rounding_var;
  double exp_window_tau_s = 0.0;
  Eigen::VectorXd exp_window;  ///< Over one hit record (ones without an exponential window).
  std::vector<std::string> warnings;
};

/// What to do about responses that still ring at their records' end, checked before it is said.
/// An exponential window of end value E over the L s after the trigger adds the decay rate
/// ln(1/E) / L to every mode; it is advised only when the one that takes the ringing to half of
/// `ringing_fraction` adds no more than the slowest mode's own decay rate `late_decay_1_s` (it at
/// most doubles that mode's damping); otherwise the record length that lets that mode decay so
/// far is advised.
struct RingingAdvice {
  double exp_window_end = 0.0;  ///< The end value advised (0: no window advised).
  double record_s = 0.0;        ///< The record length after the trigger advised (0: none).
  /// The window's added decay over the slowest mode's own (infinite when it does not decay).
  double added_over_own = 0.0;
  std::string text;
};
/// `ratio`: the worst ringing ratio (with the current window's end value `exp_window_end`, 0 for
/// none, applied); `record_s`: the record after the trigger (s).
RingingAdvice AdviseOnRinging(double ratio, double late_decay_1_s, double record_s,
                              double exp_window_end, double ringing_fraction);

/// The first half of EstimateImpactFrf: pulses, hits, their records and verdicts, the choice of
/// ImpactOptions::use_hits. Throws only for bad options or signals (a record whose hits are all
/// rejected is returned with none used).
ImpactDetection DetectImpactHits(const Eigen::Ref<const Eigen::VectorXd>& force,
                                 const Eigen::Ref<const Eigen::MatrixXd>& responses, double fs_hz,
                                 const ImpactOptions& options);

/// The window hit `hit`'s force is multiplied by: ones up to its span's `keep`, the half-cosine
/// taper, zeros after; times the exponential window.
Eigen::VectorXd ImpactForceWindow(const ImpactDetection& detection, std::size_t hit);

/// One hit's spectra before averaging: |F|^2, |X_j|^2, F^* X_j of its windowed record, and |F|^2
/// times the force window's power (for the level's noise variance). Unscaled sums of one segment.
struct HitSpectra {
  Eigen::VectorXd gff;
  Eigen::MatrixXd gxx;
  Eigen::MatrixXcd gfx;
  Eigen::VectorXd window_noise;
};

/// The spectra of hit `hit` of `detection` (made from the same signals). `fft` has
/// `detection.record_samples` points.
HitSpectra ImpactHitSpectra(const Eigen::Ref<const Eigen::VectorXd>& force,
                            const Eigen::Ref<const Eigen::MatrixXd>& responses,
                            const ImpactDetection& detection, std::size_t hit, RealFft& fft);

/// The second half of EstimateImpactFrf: the FRF from the spectra of the used hits, summed in hit
/// order (`spectra[i]` for every i with `detection.hits[i].used`; the others may be null).
/// Spectra kept from ImpactHitSpectra give the same bits as EstimateImpactFrf on the same hits.
/// InputError when no hit is used, with the reasons.
ImpactResult AverageHitSpectra(const ImpactDetection& detection,
                               const std::vector<const HitSpectra*>& spectra, double fs_hz,
                               const ImpactOptions& options, Estimator estimator,
                               Quantity response_quantity);

/// Detects the hits and returns the FRF averaged over the accepted ones (rectangular windowing
/// apart from the force/exponential windows; one segment per hit). The force window of a hit
/// spans all its pulses (a rebound is force on the structure too; cutting it off while the
/// response holds its effect biases the FRF). InputError when no hit is usable, with the reasons.
ImpactResult EstimateImpactFrf(const Eigen::Ref<const Eigen::VectorXd>& force,
                               const Eigen::Ref<const Eigen::MatrixXd>& responses, double fs_hz,
                               const ImpactOptions& options, Estimator estimator,
                               Quantity response_quantity);

/// How a force channel looks: a train of short pulses (an impact test) or a continuous excitation
/// (random, periodic, sweep), for the choice between per-hit records and Welch averaging.
struct ExcitationCheck {
  bool impact = false;
  double crest_factor = 0.0;  ///< Peak over RMS of the force about its median.
  double pulse_duty = 0.0;    ///< Fraction of the samples above 10 % of the peak.
  std::size_t pulses = 0;     ///< Pulses above 10 % of the peak (rebounds counted separately).
  std::string description;    ///< One line saying what was found and why.
};

/// An impact test when the force's crest factor is at least `kImpactCrestFactor` and the pulses
/// cover at most `kImpactMaxDuty` of the record. A random force has a crest factor of about 4-5
/// (Gaussian peaks), a sine or sweep 1.4, and both cross 10 % of their peak almost everywhere;
/// a hammer record of a few millisecond pulses in seconds of quiet has crest factors of 20 and
/// more and a duty far below 1 %.
inline constexpr double kImpactCrestFactor = 8.0;
inline constexpr double kImpactMaxDuty = 0.02;
ExcitationCheck ClassifyExcitation(const Eigen::Ref<const Eigen::VectorXd>& force, double fs_hz);

/// Largest n' <= n whose prime factors are 2, 3 and 5 (kissfft is fastest on those).
std::size_t FastFftLength(std::size_t n);

}  // namespace vibid::ident
