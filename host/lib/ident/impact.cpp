#include "vibid/ident/impact.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <numbers>
#include <sstream>

#include "vibid/common/error.hpp"

namespace vibid::ident {

void ImpactOptions::Validate() const {
  Require(trigger_fraction > 0.0 && trigger_fraction < 1.0,
          "impact: trigger fraction must be in (0, 1)");
  Require(std::isfinite(pretrigger_s), "impact: pretrigger must be finite");
  Require(record_s >= 0.0 && std::isfinite(record_s), "impact: record length must be >= 0");
  Require(force_window_s >= 0.0 && std::isfinite(force_window_s),
          "impact: force window must be >= 0");
  Require(exp_window_end >= 0.0 && exp_window_end < 1.0,
          "impact: exponential window end value must be in [0, 1)");
  Require(double_hit_window_s >= 0.0 && std::isfinite(double_hit_window_s),
          "impact: double-hit window must be >= 0");
  Require(double_hit_fraction > 0.0 && double_hit_fraction < 1.0,
          "impact: double-hit fraction must be in (0, 1)");
  Require(clip_run_samples >= 1, "impact: clipping run must be at least 1 sample");
  Require(force_dynamic_range_db > 0.0 && std::isfinite(force_dynamic_range_db),
          "impact: force dynamic range must be > 0 dB");
  Require(force_band_db >= 0.0 && std::isfinite(force_band_db),
          "impact: force band must be >= 0 dB (0: every line)");
  Require(force_excited_db >= 0.0 && std::isfinite(force_excited_db),
          "impact: force excited band must be >= 0 dB (0: the usable band)");
  Require(response_resolution_factor >= 0.0 && std::isfinite(response_resolution_factor),
          "impact: response resolution factor must be >= 0 (0: no check)");
  Require(weak_hit_fraction >= 0.0 && weak_hit_fraction < 1.0,
          "impact: weak-hit fraction must be in [0, 1) (0: no check)");
  Require(weak_hit_noise_factor >= 0.0 && std::isfinite(weak_hit_noise_factor),
          "impact: weak-hit noise factor must be >= 0 (0: no check)");
  for (std::size_t k = 0; k < use_hits.size(); ++k) {
    Require(use_hits[k] >= 1, "impact: hits to use are counted from 1");
    Require(k == 0 || use_hits[k] > use_hits[k - 1],
            "impact: hits to use must be listed once each, in increasing order");
  }
}

std::size_t FastFftLength(std::size_t n) {
  for (std::size_t m = n; m > 1; --m) {
    std::size_t r = m;
    for (std::size_t p : {2u, 3u, 5u}) {
      while (r % p == 0) r /= p;
    }
    if (r == 1) return m;
  }
  return n;
}

namespace {

struct Pulse {
  std::size_t start = 0;
  std::size_t end = 0;  // one past the last sample above the trigger
  std::size_t peak = 0;
  double peak_value = 0.0;
};

double Median(Eigen::VectorXd v) {
  const auto mid = static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.data(), v.data() + mid, v.data() + v.size());
  return v[mid];
}

// The force minus its median, in the buffer the median was selected in: a record-length signal
// costs as much in first touches of fresh pages as in arithmetic, so one buffer serves both.
Eigen::VectorXd CentredOnMedian(const Eigen::Ref<const Eigen::VectorXd>& force, double& median) {
  Eigen::VectorXd v = force;
  const auto mid = static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.data(), v.data() + mid, v.data() + v.size());
  median = v[mid];
  v = force.array() - median;
  return v;
}

std::vector<Pulse> FindPulses(const Eigen::VectorXd& f, double threshold) {
  std::vector<Pulse> pulses;
  const auto n = static_cast<std::size_t>(f.size());
  std::size_t i = 0;
  while (i < n) {
    if (std::abs(f[static_cast<Eigen::Index>(i)]) < threshold) {
      ++i;
      continue;
    }
    Pulse p;
    p.start = i;
    // Noise near the threshold on the flanks must not split one pulse: allow two-sample dips.
    std::size_t last_above = i;
    while (i < n && i <= last_above + 2) {
      const double v = std::abs(f[static_cast<Eigen::Index>(i)]);
      if (v >= threshold) {
        last_above = i;
        if (v > p.peak_value) {
          p.peak_value = v;
          p.peak = i;
        }
      }
      ++i;
    }
    p.end = last_above + 1;
    pulses.push_back(p);
    i = p.end;
  }
  return pulses;
}

// A channel's rails: the converter's limits, where they are known
// (ImpactOptions::converter_limits); a run on either is a clip, wherever the channel rests (a
// 12-bit channel resting near code 2048 that repeats its own top code 2077 inside 0..4095 is not
// clipped). Where they are unknown the channel is not checked: its own largest value says
// nothing of where its converter ends (an encoder's slow peak repeats it, a good hit well inside
// the range has one), and a guess rejects good hits and passes clipped ones.
struct Rails {
  double lo = 0.0;
  double hi = 0.0;
  bool use_lo = false;
  bool use_hi = false;
};

Rails RailsOf(const ImpactOptions& options, std::size_t channel) {
  if (channel < options.converter_limits.size() && options.converter_limits[channel].Known()) {
    const ImpactOptions::ConverterLimits& l = options.converter_limits[channel];
    return {l.lo, l.hi, true, true};
  }
  return {};
}

// A run of consecutive samples within a hair of a rail.
bool Clipped(const double* x, std::size_t n, const Rails& rails, std::size_t min_run) {
  const double tol = 1e-9 * std::max(rails.hi - rails.lo, 1e-300);
  std::size_t run_hi = 0;
  std::size_t run_lo = 0;
  for (std::size_t i = 0; i < n; ++i) {
    run_hi = (rails.use_hi && x[i] >= rails.hi - tol) ? run_hi + 1 : 0;
    run_lo = (rails.use_lo && x[i] <= rails.lo + tol) ? run_lo + 1 : 0;
    if (run_hi >= min_run || run_lo >= min_run) return true;
  }
  return false;
}

}  // namespace

ExcitationCheck ClassifyExcitation(const Eigen::Ref<const Eigen::VectorXd>& force, double fs_hz) {
  Require(fs_hz > 0.0 && std::isfinite(fs_hz), "sample rate must be > 0");
  ExcitationCheck out;
  if (force.size() < 16) {
    out.description = "force record too short to classify";
    return out;
  }
  double median = 0.0;
  const Eigen::VectorXd centred = CentredOnMedian(force, median);
  const double peak = centred.cwiseAbs().maxCoeff();
  const double rms = std::sqrt(centred.squaredNorm() / static_cast<double>(centred.size()));
  if (!(peak > 0.0) || !(rms > 0.0)) {
    out.description = "force channel is constant";
    return out;
  }
  out.crest_factor = peak / rms;
  const std::vector<Pulse> pulses = FindPulses(centred, 0.1 * peak);
  std::size_t above = 0;
  for (const Pulse& p : pulses) above += p.end - p.start;
  out.pulses = pulses.size();
  out.pulse_duty = static_cast<double>(above) / static_cast<double>(centred.size());
  out.impact = out.crest_factor >= kImpactCrestFactor && out.pulse_duty <= kImpactMaxDuty;
  std::ostringstream d;
  d.precision(3);
  d << "force has " << out.pulses << " pulse(s) over " << 100.0 * out.pulse_duty
    << " % of the record, crest factor " << out.crest_factor;
  out.description = d.str();
  return out;
}

RingingAdvice AdviseOnRinging(double ratio, double late_decay_1_s, double record_s,
                              double exp_window_end, double ringing_fraction) {
  RingingAdvice a;
  const double target = 0.5 * ringing_fraction;
  const double current_end = exp_window_end > 0.0 ? exp_window_end : 1.0;
  const double raw = ratio / current_end;  // the ringing without a window
  if (!(raw > target) || !(record_s > 0.0)) return a;
  // Two significant digits, rounded down so that the window does take the ringing that far.
  const double end = std::floor(100.0 * target / raw) / 100.0;
  const double added_1_s = std::log(1.0 / std::max(end, 1e-3)) / record_s;
  const bool decays = late_decay_1_s > 0.0 && std::isfinite(late_decay_1_s);
  a.added_over_own = decays ? added_1_s / late_decay_1_s : std::numeric_limits<double>::infinity();
  std::ostringstream t;
  t.precision(2);
  if (decays && a.added_over_own <= 1.0 && end > 0.0) {
    a.exp_window_end = end;
    t << "an exponential window --exp-window " << end << " takes it to " << 100.0 * target
      << " %: it adds a decay rate of " << added_1_s
      << " 1/s, no more than the own decay rate of the mode that rings longest (" << late_decay_1_s
      << " 1/s), and the modes' damping is corrected for it (a longer record does it too)";
    a.text = t.str();
    return a;
  }
  if (decays) {
    a.record_s = record_s + std::log(raw / target) / late_decay_1_s;
    t << "records of at least " << std::setprecision(3) << a.record_s
      << " s after the hit (hits that far apart, --record-s where they are) let the mode that "
         "rings longest (decay rate "
      << std::setprecision(2) << late_decay_1_s << " 1/s) ring down to " << 100.0 * target
      << " %; an exponential window that does it (--exp-window " << end << ") adds "
      << a.added_over_own
      << " times that mode's own decay, which widens its peak as many times over and leaves its "
         "damping a small difference of large numbers: not advised";
  } else {
    t << "the responses hardly decay over the record: records several times longer (hits "
         "further apart) let them die out; an exponential window would bury the slowest mode "
         "under its own added damping";
  }
  a.text = t.str();
  return a;
}

namespace {

// A hit and its rebounds: pulses closer than the double-hit window to the previous one.
using PulseGroup = std::vector<Pulse>;

std::vector<PulseGroup> GroupRebounds(const std::vector<Pulse>& pulses,
                                      std::size_t rebound_samples) {
  std::vector<PulseGroup> groups;
  for (const Pulse& p : pulses) {
    if (!groups.empty() && p.start <= groups.back().back().end + rebound_samples) {
      groups.back().push_back(p);
    } else {
      groups.push_back({p});
    }
  }
  return groups;
}

// Samples per hit record and before the trigger.
struct RecordLayout {
  std::size_t record = 0;
  std::size_t pre = 0;
};

RecordLayout ChooseRecord(const std::vector<PulseGroup>& groups, std::size_t n, double fs_hz,
                          const ImpactOptions& options) {
  RecordLayout layout;
  std::size_t& record = layout.record;
  if (options.record_s > 0.0) {
    record = static_cast<std::size_t>(std::llround(options.record_s * fs_hz));
  } else {
    record = n - groups.front().front().start;
    for (std::size_t g = 1; g < groups.size(); ++g) {
      record = std::min(record, groups[g].front().start - groups[g - 1].front().start);
    }
    if (groups.size() > 1) {
      // The last hit's tail is often cut short by the end of the file; do not let it set the
      // length.
      record = std::max<std::size_t>(record, 16);
    }
  }
  if (options.pretrigger_s >= 0.0) {
    layout.pre = static_cast<std::size_t>(std::llround(options.pretrigger_s * fs_hz));
  } else {
    layout.pre = std::min(record / 64, groups.front().front().start);
  }
  if (options.record_s <= 0.0)
    record = FastFftLength(record + (groups.size() > 1 ? 0 : layout.pre));
  Require(record >= 16, "impact: hit records would be shorter than 16 samples");
  Require(layout.pre < record / 2, "impact: pretrigger must be shorter than half the hit record");
  return layout;
}

// Exponential window from the trigger, of value `end_value` at the record end (all ones for 0);
// `tau_s` receives its time constant (0 for none).
Eigen::VectorXd ExponentialWindow(const RecordLayout& layout, double fs_hz, double end_value,
                                  double& tau_s) {
  tau_s = 0.0;
  if (end_value > 0.0)
    tau_s = static_cast<double>(layout.record - layout.pre) / fs_hz / std::log(1.0 / end_value);
  Eigen::VectorXd window = Eigen::VectorXd::Ones(static_cast<Eigen::Index>(layout.record));
  if (tau_s > 0.0) {
    for (std::size_t i = layout.pre; i < layout.record; ++i) {
      window[static_cast<Eigen::Index>(i)] =
          std::exp(-static_cast<double>(i - layout.pre) / fs_hz / tau_s);
    }
  }
  return window;
}

// The channels of the record as the hit classification reads them.
struct ImpactChannels {
  const Eigen::Ref<const Eigen::VectorXd>& force;
  const Eigen::VectorXd& centred_force;
  const Eigen::Ref<const Eigen::MatrixXd>& responses;
  std::vector<Rails> rails;  // force first, then one per response
  double force_noise_sd = 0.0;
  std::vector<double> response_noise_power;  // per response, from the lead before the first hit
};

// A second pulse counts only above this many standard deviations of the force channel's noise
// (normal noise passes it once in 5e8 samples: once in 10^5 records of 4096 samples).
constexpr double kDoubleHitNoiseFactor = 6.0;
// Within the double-hit window after the first pulse, where a rebound lands, the level is set so
// that noise alone calls one good hit in 10^4 double over that window's samples: a few dozen at
// an analyzer's rates, where 6 standard deviations hid a rebound of 12 % of the peak under force
// noise of 2 % of it (the level is at least double_hit_fraction of the peak all the same).
constexpr double kReboundFalseAlarm = 1e-4;

// The level, in standard deviations of normal noise, that one of `samples` samples exceeds with
// probability `p` (two-sided): erfc(z / sqrt 2) = p / samples, by bisection.
double NoiseFactorFor(double p, std::size_t samples) {
  const double per_sample = p / static_cast<double>(std::max<std::size_t>(samples, 1));
  double lo = 0.0;
  double hi = 40.0;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (std::erfc(mid / std::numbers::sqrt2) > per_sample ? lo : hi) = mid;
  }
  return std::min(hi, kDoubleHitNoiseFactor);
}

// How far a hit's responses still ring at its record's end: per response, the RMS over the
// record's last eighth over the RMS over the first eighth after the trigger, both about the
// record's median, each less the noise power of the quiet lead before the first hit; the largest
// over the responses. With it, that response's late decay rate (1/s): from its RMS over the
// last two eighths, where the mode that rings longest dominates (0 where it does not
// decay measurably).
struct Ringing {
  double ratio = 0.0;
  double late_decay_1_s = 0.0;
};

Ringing RingingOf(const Eigen::Ref<const Eigen::MatrixXd>& responses, std::size_t s0,
                  std::size_t record, std::size_t pre, double fs_hz,
                  const std::vector<double>& noise_power) {
  const std::size_t eighth = (record - pre) / 8;
  Ringing worst;
  if (eighth < 4) return worst;
  for (Eigen::Index j = 0; j < responses.cols(); ++j) {
    const Eigen::VectorXd x =
        responses.col(j).segment(static_cast<Eigen::Index>(s0), static_cast<Eigen::Index>(record));
    const double rest = Median(x);
    const auto power = [&](std::size_t from, std::size_t count) {
      return (x.segment(static_cast<Eigen::Index>(from), static_cast<Eigen::Index>(count)).array() -
              rest)
          .square()
          .mean();
    };
    // The noise power comes from the quiet lead before the first hit (a pretrigger may hold the
    // previous hit's ringing, which is what this check looks for).
    const double noise = static_cast<std::size_t>(j) < noise_power.size()
                             ? noise_power[static_cast<std::size_t>(j)]
                             : 0.0;
    const double early = power(pre, eighth) - noise;
    const double late = std::max(0.0, power(record - eighth, eighth) - noise);
    if (!(early > 0.0)) continue;
    const double ratio = std::sqrt(late / early);
    if (ratio <= worst.ratio) continue;
    worst.ratio = ratio;
    const double seventh = power(record - 2 * eighth, eighth) - noise;
    // Amplitude decay over one eighth: half the log of the power ratio.
    worst.late_decay_1_s =
        (late > 0.0 && seventh > late)
            ? 0.5 * std::log(seventh / late) / (static_cast<double>(eighth) / fs_hz)
            : 0.0;
  }
  return worst;
}

// Flags a hit as truncated, double or clipped, with a note saying why.
Hit ClassifyHit(const PulseGroup& group, const ImpactChannels& ch, const RecordLayout& layout,
                double fs_hz, const ImpactOptions& options, HitSpan& span) {
  const auto n = static_cast<std::size_t>(ch.force.size());
  const std::size_t pre = layout.pre;
  const std::size_t record = layout.record;
  const Pulse& first = group.front();
  const Pulse& last = group.back();
  Hit hit;
  hit.trigger_index = first.start;
  hit.peak_index = first.peak;
  hit.peak_n = ch.centred_force[static_cast<Eigen::Index>(first.peak)];
  hit.t_s = static_cast<double>(first.start) / fs_hz;
  hit.pulse_width_s = static_cast<double>(first.end - first.start) / fs_hz;
  hit.pulses = group.size();
  std::vector<std::string> notes;
  if (first.start < pre || first.start - pre + record > n) {
    hit.truncated = true;
    notes.push_back(first.start < pre ? "too little data before the hit for the pretrigger"
                                      : "record ends before the hit's window");
  }
  const std::size_t s0 = first.start >= pre ? first.start - pre : 0;
  const std::size_t s1 = std::min(n, s0 + record);
  // Any other pulse inside this hit's record is a second impact on the structure: a pulse above
  // `double_hit_fraction` of this hit's own peak (and clear of the force noise), searched at that
  // level and not at the trigger, which the record's largest hit sets: a later, larger hit must
  // not turn this hit's double hit into a single one. A rebound within the double-hit window of
  // the pulse before it is force on the structure too: the force window spans it.
  std::size_t group_end = last.end;
  {
    const Eigen::VectorXd& cf = ch.centred_force;
    const double level = std::max(options.double_hit_fraction * first.peak_value,
                                  kDoubleHitNoiseFactor * ch.force_noise_sd);
    const auto rebound =
        static_cast<std::size_t>(std::llround(options.double_hit_window_s * fs_hz));
    const double rebound_level =
        std::max(options.double_hit_fraction * first.peak_value,
                 NoiseFactorFor(kReboundFalseAlarm, rebound) * ch.force_noise_sd);
    // The first pulse's falling flank is followed down to the rebound's level, then the window.
    std::size_t rebound_until = std::numeric_limits<std::size_t>::max();
    const auto above = [&](std::size_t k) {
      return std::abs(cf[static_cast<Eigen::Index>(k)]) >=
             (k < rebound_until ? rebound_level : level);
    };
    // Past the first pulse's falling flank at that level (two-sample dips of noise allowed).
    const auto pulse_end = [&](std::size_t k) {
      std::size_t last_above = k;
      while (k < s1 && k <= last_above + 2) {
        if (above(k)) last_above = k;
        ++k;
      }
      return last_above + 1;
    };
    std::size_t prev_end = pulse_end(first.peak);
    rebound_until = prev_end + rebound;
    for (std::size_t k = prev_end; k < s1; ++k) {
      if (!above(k)) continue;
      hit.double_hit = true;
      const std::size_t end = pulse_end(k);
      if (k <= prev_end + rebound) {
        group_end = std::max(group_end, end);
        prev_end = end;
      }
      k = end;
    }
  }
  if (hit.double_hit) notes.push_back("double hit");
  if (Clipped(ch.force.data() + s0, s1 - s0, ch.rails[0], options.clip_run_samples)) {
    hit.clipped = true;
    notes.push_back("force channel clipped");
  }
  for (Eigen::Index j = 0; j < ch.responses.cols(); ++j) {
    if (Clipped(ch.responses.col(j).data() + s0, s1 - s0, ch.rails[static_cast<std::size_t>(j) + 1],
                options.clip_run_samples)) {
      hit.clipped = true;
      notes.push_back("response " + std::to_string(j + 1) + " clipped");
    }
  }
  if (!hit.truncated && options.ringing_fraction > 0.0) {
    // An exponential window takes the ringing down to its end value before the spectra see it.
    const Ringing ringing =
        RingingOf(ch.responses, s0, record, pre, fs_hz, ch.response_noise_power);
    hit.ringing_ratio =
        ringing.ratio * (options.exp_window_end > 0.0 ? options.exp_window_end : 1.0);
    hit.ringing_decay_1_s = ringing.late_decay_1_s;
    if (hit.ringing_ratio >= options.ringing_fraction) {
      hit.ringing = true;
      std::ostringstream note;
      note.precision(2);
      note << "still ringing at the record's end (" << 100.0 * hit.ringing_ratio
           << " % of its level after the hit): see the record's warning for a record long enough";
      notes.push_back(note.str());
    }
  }
  for (std::size_t k = 0; k < notes.size(); ++k) hit.note += (k ? "; " : "") + notes[k];
  // Force window: keep through the hit's last pulse plus the first pulse's width as margin.
  const std::size_t width = std::max<std::size_t>(first.end - first.start, 1);
  std::size_t keep = pre + (group_end - first.start) + width;
  if (options.force_window_s > 0.0)
    keep = pre + static_cast<std::size_t>(std::llround(options.force_window_s * fs_hz));
  span = {s0, std::min(keep, record), width};
  return hit;
}

// Too weak against the hits that are fine otherwise (their median peak) or against the force
// channel's noise: flagged, with the level it fell short of.
void FlagWeakHits(const ImpactOptions& options, double noise_sd, std::vector<Hit>& hits) {
  std::vector<double> peaks;
  for (const Hit& h : hits) {
    if (!h.truncated && !h.double_hit && !h.clipped) peaks.push_back(std::abs(h.peak_n));
  }
  double median = 0.0;
  if (!peaks.empty()) {
    const auto mid = static_cast<std::ptrdiff_t>(peaks.size() / 2);
    std::nth_element(peaks.begin(), peaks.begin() + mid, peaks.end());
    median = peaks[static_cast<std::size_t>(mid)];
  }
  const double relative_floor = options.weak_hit_fraction * median;
  const double noise_floor = options.weak_hit_noise_factor * noise_sd;
  for (Hit& h : hits) {
    if (h.truncated) continue;
    const double peak = std::abs(h.peak_n);
    std::ostringstream note;
    note.precision(4);
    if (peak < relative_floor) {
      note << "too weak: peak " << peak << " below " << options.weak_hit_fraction
           << " of the median peak " << median;
    } else if (peak < noise_floor) {
      note << "too weak: peak " << peak << " below " << options.weak_hit_noise_factor
           << " force noise standard deviations (" << noise_floor << ")";
    } else {
      continue;
    }
    h.weak = true;
    h.note += (h.note.empty() ? "" : "; ") + note.str();
  }
}

// Double hits are used after all when every complete hit is one (a rig that always rebounds).
bool KeepDoubleHits(const ImpactOptions& options, const std::vector<Hit>& hits,
                    std::vector<std::string>& warnings) {
  bool all_double = true;
  bool any_candidate = false;
  for (const Hit& h : hits) {
    if (h.truncated) continue;
    any_candidate = true;
    all_double = all_double && h.double_hit && !h.clipped;
  }
  if (options.reject_bad_hits && any_candidate && all_double) {
    warnings.push_back(
        "every hit is a double hit: used all the same, each force window spanning the hit's "
        "pulses");
  }
  return !options.reject_bad_hits || (any_candidate && all_double);
}

// The hits to average: the listed ones (a truncated one refused), else the verdicts.
void ChooseHits(const ImpactOptions& options, ImpactDetection& d) {
  if (!options.use_hits.empty()) {
    for (Hit& h : d.hits) h.used = false;
    for (const std::size_t k : options.use_hits) {
      Require(k <= d.hits.size(), "impact: hit " + std::to_string(k) +
                                      " asked for, but the record has " +
                                      std::to_string(d.hits.size()) + " hit(s)");
      Hit& h = d.hits[k - 1];
      Require(!h.truncated, "impact: hit " + std::to_string(k) + " (at " + std::to_string(h.t_s) +
                                " s) cannot be used: " + h.note);
      h.used = true;
    }
    return;
  }
  const bool keep_doubles = KeepDoubleHits(options, d.hits, d.warnings);
  for (Hit& hit : d.hits) {
    hit.used = !hit.truncated && (!options.reject_bad_hits || (!hit.clipped && !hit.weak)) &&
               (keep_doubles || !hit.double_hit);
  }
}

// Used hits whose responses still ring at their record's end: said once for the record, with
// advice checked against the record before it is given. An exponential window of end value E
// over the L seconds after the trigger adds a decay rate ln(1/E) / L to every mode; the modes'
// damping is corrected for it, but where it is larger than the slowest mode's own decay rate
// the window buries that mode (its peak widens many times over and sinks into the noise, its
// damping a small difference of large numbers). So a window is advised only where the one that
// takes the ringing to half the flag's level adds no more than the slowest ringing mode's own
// decay (read from the record's late part); otherwise the record length that lets that mode
// decay to that level is advised.
void WarnOfRinging(const ImpactOptions& options, std::size_t record, std::size_t pre, double fs_hz,
                   ImpactDetection& d) {
  std::size_t ringing = 0;
  std::size_t used = 0;
  double worst = 0.0;
  double slowest_1_s = std::numeric_limits<double>::infinity();
  for (const Hit& h : d.hits) {
    if (!h.used) continue;
    ++used;
    if (!h.ringing) continue;
    ++ringing;
    worst = std::max(worst, h.ringing_ratio);
    slowest_1_s = std::min(slowest_1_s, h.ringing_decay_1_s);
  }
  if (ringing == 0) return;
  const RingingAdvice advice =
      AdviseOnRinging(worst, slowest_1_s, static_cast<double>(record - pre) / fs_hz,
                      options.exp_window_end, options.ringing_fraction);
  std::ostringstream w;
  w.precision(2);
  w << ringing << " of " << used << " used hit(s) still ring at their record's end (up to "
    << 100.0 * worst
    << " % of the level after the hit): the FRF holds the cut-off ringing as leakage, which the "
       "pole-residue model (lscf, lsce) carries but peak picking and the curve fit do not; "
    << advice.text;
  d.warnings.push_back(w.str());
}

// The mean of `count` samples of a column from `start`, summed as Eigen sums a column held whole
// in its own vector: the vectorized sum splits at aligned addresses, so the samples are copied at
// the phase they would have there. The mean is then the same bits however the caller holds the
// channel (a column of a wider matrix, a vector with spare capacity).
double MeanAsWholeColumn(const double* column, std::size_t start, std::size_t count) {
  constexpr std::size_t kPhase = EIGEN_DEFAULT_ALIGN_BYTES / sizeof(double);
  const std::size_t phase = kPhase > 0 ? start % kPhase : 0;
  Eigen::VectorXd buffer(static_cast<Eigen::Index>(count + phase));
  std::copy(column + start, column + start + count, buffer.data() + phase);
  return Eigen::Map<const Eigen::VectorXd>(buffer.data() + phase, static_cast<Eigen::Index>(count))
      .mean();
}

// With double hits averaged, the force spectrum has notches: lines where it falls below the
// dynamic range carry no FRF. A single pulse has them too, above its band (a half-sine of width w
// first at 1.5 / w): there the hits' other content (the previous hits' ringing, noise) over a
// vanishing force makes H1 a spike that dwarfs every resonance, and a noise-free record, whose
// coherence does not mark those lines, had its band chosen around the spike. Every impact FRF is
// therefore limited to the force's band (ImpactOptions::force_band_db), whatever the noise.
// The first line above DC where the force auto-spectrum falls `range_db` below its largest value
// (the DC line aside), or the number of lines when it never does.
Eigen::Index FirstFadedLine(const CrossSpectra& spectra, double range_db) {
  const Eigen::Index lines = spectra.freq_hz.size();
  const double top = spectra.gff.tail(lines - 1).maxCoeff();
  const double floor = top * std::pow(10.0, -range_db / 10.0);
  Eigen::Index k = 1;
  while (k < lines && spectra.gff[k] >= floor) ++k;
  return k;
}

void LimitToForceBand(const CrossSpectra& spectra, double range_db, bool doubles,
                      ImpactResult& result) {
  const Eigen::Index lines = spectra.freq_hz.size();
  const Eigen::Index k = FirstFadedLine(spectra, range_db);
  if (k == lines) return;
  result.usable_max_hz = spectra.freq_hz[k - 1];
  result.frf.coherence.bottomRows(lines - k).setZero();
  // A single pulse's band is what a hammer gives: the coherence of 0 above it says so in the FRF
  // itself (ImpactResult::usable_max_hz), without a warning on every hammer test.
  if (!doubles) return;
  std::ostringstream w;
  w.precision(4);
  w << "double hits in the average: the force spectrum stays within " << range_db
    << " dB of its peak from " << result.usable_min_hz << " to " << result.usable_max_hz
    << " Hz; lines above carry no FRF (coherence set to 0)";
  result.warnings.push_back(w.str());
}

// The last line before the force auto-spectrum first falls `range_db` below its largest value
// (the DC line aside), or the last line. The lines above carry a response to a force that no
// longer drives the structure: with a single average every line's coherence is 1, so only the
// force says where H1 turns into the record's noise over the pulse's notch (a four-mass chain
// with encoders, 12-bit: 60-1300 "peaks" at 650-730 Hz, and the poles placed there took the
// place of a real mode).
double ExcitedMaxHz(const CrossSpectra& spectra, double range_db) {
  return spectra.freq_hz[FirstFadedLine(spectra, range_db) - 1];
}

// Per column, q^2 / 12 for its smallest nonzero step between consecutive samples q.
std::vector<double> RoundingVariances(const Eigen::Ref<const Eigen::MatrixXd>& responses) {
  std::vector<double> out;
  for (Eigen::Index j = 0; j < responses.cols(); ++j) {
    double q = std::numeric_limits<double>::infinity();
    for (Eigen::Index i = 1; i < responses.rows(); ++i) {
      const double step = std::abs(responses(i, j) - responses(i - 1, j));
      if (step > 0.0) q = std::min(q, step);
    }
    out.push_back(std::isfinite(q) ? q * q / 12.0 : 0.0);
  }
  return out;
}

// Lines above `from_hz` where a response's auto-spectrum is below `factor` times its rounding
// noise carry no FRF for that response (ImpactOptions::response_resolution_factor). `gxx` are
// the scaled sums over `used` hits; each hit's responses are multiplied by `exp_window`. Only
// where the force has started to fade (10 dB down, the strict end of the hammer's rule): in the
// modes' band a 12-bit channel's antiresonance lines fell below it too, and weighing them out
// moved the fits (a two-mass test's driving point no longer found).
void MaskBelowResolution(const Eigen::MatrixXd& gxx, const std::vector<double>& rounding_var,
                         const Eigen::VectorXd& exp_window, double scale, std::size_t used,
                         double factor, double from_hz, Frf& frf) {
  if (!(factor > 0.0)) return;
  const double window_power = exp_window.squaredNorm();
  for (Eigen::Index j = 0; j < gxx.cols() && static_cast<std::size_t>(j) < rounding_var.size();
       ++j) {
    const double floor = factor * scale * static_cast<double>(used) *
                         rounding_var[static_cast<std::size_t>(j)] * window_power;
    for (Eigen::Index k = 0; k < gxx.rows(); ++k)
      if (frf.freq_hz[k] > from_hz && gxx(k, j) < floor) frf.coherence(k, j) = 0.0;
  }
}

// Variance of the force channel's noise: from the median absolute deviation of the median-
// centred force (the hits are a few per cent of the samples at most, which the median ignores;
// 1.4826 makes it the standard deviation of normal noise).
double ForceNoiseVariance(const Eigen::VectorXd& centred) {
  Eigen::VectorXd a = centred.cwiseAbs();
  const auto mid = static_cast<std::ptrdiff_t>(a.size() / 2);
  std::nth_element(a.data(), a.data() + mid, a.data() + a.size());
  const double sd = 1.4826 * a[mid];
  return sd * sd;
}

// Per line: the variance of the relative error of |H1| from force noise inside the windows,
// sigma^2 sum_h |F_h|^2 W_h / (sum_h |F_h|^2)^2, halved for the real part (the magnitude's share
// of a complex error). 0 where the force has no energy.
Eigen::VectorXd LevelRelativeVariance(double noise_var, const Eigen::VectorXd& window_noise,
                                      const Eigen::VectorXd& gff) {
  Eigen::VectorXd v = Eigen::VectorXd::Zero(gff.size());
  for (Eigen::Index i = 0; i < gff.size(); ++i) {
    if (gff[i] > 0.0) v[i] = 0.5 * noise_var * window_noise[i] / (gff[i] * gff[i]);
  }
  return v;
}

CrossSpectra ZeroSpectra(std::size_t record, Eigen::Index responses, double fs_hz) {
  const auto lines = static_cast<Eigen::Index>(record / 2 + 1);
  CrossSpectra spectra;
  spectra.freq_hz = Eigen::VectorXd::LinSpaced(
      lines, 0.0, static_cast<double>(lines - 1) * fs_hz / static_cast<double>(record));
  spectra.gff = Eigen::VectorXd::Zero(lines);
  spectra.gxx = Eigen::MatrixXd::Zero(lines, responses);
  spectra.gfx = Eigen::MatrixXcd::Zero(lines, responses);
  return spectra;
}

// A first hit with too little before it to see the force quiet: fewer samples than two pulse
// widths and 16 more, the lead the responses' noise is read from (an explicit pretrigger that
// does not fit refuses the hit as truncated). The record was started by the hit, as an analyzer
// without a pretrigger does: the force before it is unseen, so a touch or a rising flank there is
// lost, and where the hit starts on the first sample the record's start cuts the pulse.
void WarnOfMissingPretrigger(const Pulse& first, double fs_hz, const ImpactOptions& options,
                             std::vector<std::string>& warnings) {
  if (options.pretrigger_s >= 0.0) return;
  const std::size_t lead = 2 * (first.end - first.start) + 16;
  if (first.start >= lead) return;
  std::ostringstream w;
  w.precision(3);
  if (first.start == 0) {
    w << "the first hit starts on the record's first sample: its rise and any force before it "
         "are unseen, and the record's start cuts the pulse";
  } else {
    w << "the first hit starts " << first.start << " sample(s) ("
      << 1e3 * static_cast<double>(first.start) / fs_hz
      << " ms) into the record, short of the quiet lead of " << lead
      << " samples (two pulse widths and 16) that shows the force before it and the responses' "
         "noise";
  }
  w << "; record with a pretrigger (the analyzer's pretrigger or trigger delay, or start the "
       "acquisition earlier) so that the force is quiet before each hit";
  warnings.push_back(w.str());
}

}  // namespace

ImpactDetection DetectImpactHits(const Eigen::Ref<const Eigen::VectorXd>& force,
                                 const Eigen::Ref<const Eigen::MatrixXd>& responses, double fs_hz,
                                 const ImpactOptions& options) {
  options.Validate();
  Require(fs_hz > 0.0 && std::isfinite(fs_hz), "sample rate must be > 0");
  Require(responses.rows() == force.size(), "force and responses differ in length");
  Require(responses.cols() >= 1, "at least one response channel is needed");
  const auto n = static_cast<std::size_t>(force.size());
  Require(n >= 16, "impact record is too short (" + std::to_string(n) + " samples)");

  ImpactDetection d;
  const Eigen::VectorXd centred = CentredOnMedian(force, d.baseline);
  const double peak_all = centred.cwiseAbs().maxCoeff();
  Require(peak_all > 0.0, "force channel is constant: no hit to detect");
  d.trigger_level = options.trigger_fraction * peak_all;
  const std::vector<Pulse> pulses = FindPulses(centred, d.trigger_level);
  const std::vector<PulseGroup> groups = GroupRebounds(
      pulses, static_cast<std::size_t>(std::llround(options.double_hit_window_s * fs_hz)));
  Require(!groups.empty(), "no hit found in the force channel");

  const RecordLayout layout = ChooseRecord(groups, n, fs_hz, options);
  d.record_samples = layout.record;
  d.pretrigger_samples = layout.pre;
  d.exp_window = ExponentialWindow(layout, fs_hz, options.exp_window_end, d.exp_window_tau_s);
  d.force_noise_var = ForceNoiseVariance(centred);
  d.response_rounding_var = RoundingVariances(responses);

  Require(options.converter_limits.empty() ||
              options.converter_limits.size() == static_cast<std::size_t>(responses.cols()) + 1,
          "impact: converter limits must be given for the force and every response (" +
              std::to_string(responses.cols() + 1) + " channels), or for none");
  ImpactChannels channels{
      force, centred, responses, {RailsOf(options, 0)}, std::sqrt(d.force_noise_var), {}};
  // The lead before the first pulse, less a margin of the pulse's width: the responses' noise.
  {
    const std::size_t first = groups.front().front().start;
    const std::size_t width = groups.front().front().end - first;
    const std::size_t lead = first > 2 * width ? first - 2 * width : 0;
    for (Eigen::Index j = 0; j < responses.cols(); ++j) {
      double p = 0.0;
      if (lead >= 16) {
        const Eigen::VectorXd x = responses.col(j).head(static_cast<Eigen::Index>(lead));
        p = (x.array() - x.mean()).square().mean();
      }
      channels.response_noise_power.push_back(p);
    }
  }
  for (Eigen::Index j = 0; j < responses.cols(); ++j)
    channels.rails.push_back(RailsOf(options, static_cast<std::size_t>(j) + 1));
  {
    // A check that cannot be made is said, never guessed.
    std::vector<std::string> unchecked;
    for (std::size_t c = 0; c < channels.rails.size(); ++c) {
      if (!channels.rails[c].use_lo)
        unchecked.push_back(c == 0 ? "the force" : "response " + std::to_string(c));
    }
    if (!unchecked.empty()) {
      std::string list;
      for (std::size_t i = 0; i < unchecked.size(); ++i)
        list += (i == 0 ? "" : i + 1 == unchecked.size() ? " and " : ", ") + unchecked[i];
      d.warnings.push_back(
          "clip check unavailable for " + list +
          ": the converters' rails are not stated (a recording's sidecar REC.csv.json states "
          "them, as `vibid acquire` writes it)");
    }
  }
  WarnOfMissingPretrigger(groups.front().front(), fs_hz, options, d.warnings);
  d.spans.resize(groups.size());
  for (std::size_t g = 0; g < groups.size(); ++g) {
    d.hits.push_back(ClassifyHit(groups[g], channels, layout, fs_hz, options, d.spans[g]));
  }
  FlagWeakHits(options, std::sqrt(d.force_noise_var), d.hits);
  ChooseHits(options, d);
  WarnOfRinging(options, layout.record, layout.pre, fs_hz, d);
  return d;
}

Eigen::VectorXd ImpactForceWindow(const ImpactDetection& detection, std::size_t hit) {
  Require(hit < detection.spans.size(), "impact: no such hit");
  const HitSpan& span = detection.spans[hit];
  const std::size_t record = detection.record_samples;
  const std::size_t keep = span.keep;
  const std::size_t taper = std::min(span.taper, record - keep);
  Eigen::VectorXd window(static_cast<Eigen::Index>(record));
  for (std::size_t i = 0; i < record; ++i) {
    double w = 0.0;
    if (i < keep) {
      w = 1.0;
    } else if (i < keep + taper) {
      w = 0.5 * (1.0 + std::cos(std::numbers::pi * static_cast<double>(i - keep + 1) /
                                static_cast<double>(taper + 1)));
    }
    w *= detection.exp_window[static_cast<Eigen::Index>(i)];
    window[static_cast<Eigen::Index>(i)] = w;
  }
  return window;
}

// One hit's spectra: offsets from the pretrigger (else the force baseline), the force kept up to
// span.keep then tapered to zero by a half cosine as long as the first pulse, every channel under
// the exponential window.
HitSpectra ImpactHitSpectra(const Eigen::Ref<const Eigen::VectorXd>& force,
                            const Eigen::Ref<const Eigen::MatrixXd>& responses,
                            const ImpactDetection& detection, std::size_t hit, RealFft& fft) {
  Require(hit < detection.spans.size(), "impact: no such hit");
  Require(fft.size() == detection.record_samples, "impact: FFT length differs from the record");
  const HitSpan& span = detection.spans[hit];
  const std::size_t record = detection.record_samples;
  const std::size_t pre = detection.pretrigger_samples;
  Require(span.start + record <= static_cast<std::size_t>(force.size()) &&
              responses.rows() == force.size(),
          "impact: the hit's record runs past the signals");
  const Eigen::VectorXd& exp_window = detection.exp_window;
  // Offsets from the pretrigger's samples before the pulse: the pulse rises below the trigger
  // threshold for up to a sample or so, and that sample (and the response's direct part of it)
  // averaged into the offset was taken off the whole force window: |H1| came out up to 2 % high
  // with a pretrigger of 10 ms, 0.1 to 0.3 % with the default 1/64 of a 3.5 s record.
  const std::size_t quiet = pre > span.taper ? pre - span.taper : 0;
  const double f_offset =
      quiet >= 4 ? MeanAsWholeColumn(force.data(), span.start, quiet) : detection.baseline;
  const Eigen::VectorXd window = ImpactForceWindow(detection, hit);
  Eigen::VectorXd fbuf(static_cast<Eigen::Index>(record));
  double window_power = 0.0;  // sum of the squared force window: white noise's power through it
  for (std::size_t i = 0; i < record; ++i) {
    const double w = window[static_cast<Eigen::Index>(i)];
    window_power += w * w;
    fbuf[static_cast<Eigen::Index>(i)] =
        (force[static_cast<Eigen::Index>(span.start + i)] - f_offset) * w;
  }
  Eigen::VectorXcd fspec;
  fft.Transform(fbuf.data(), fspec);
  HitSpectra out;
  out.gff = fspec.cwiseAbs2();
  // H1's error from force noise N in the window is sum F* N / sum |F|^2; its variance per unit
  // noise variance has the numerator sum |F|^2 W (W = window_power).
  out.window_noise = window_power * fspec.cwiseAbs2();
  out.gxx.resize(fspec.size(), responses.cols());
  out.gfx.resize(fspec.size(), responses.cols());
  Eigen::VectorXd xbuf(static_cast<Eigen::Index>(record));
  Eigen::VectorXcd xspec;
  for (Eigen::Index j = 0; j < responses.cols(); ++j) {
    const double* x = responses.col(j).data();
    const double x_offset = quiet >= 4 ? MeanAsWholeColumn(x, span.start, quiet) : 0.0;
    xbuf = (Eigen::Map<const Eigen::VectorXd>(x + span.start, static_cast<Eigen::Index>(record))
                .array() -
            x_offset) *
           exp_window.array();
    fft.Transform(xbuf.data(), xspec);
    out.gxx.col(j) = xspec.cwiseAbs2();
    out.gfx.col(j).array() = fspec.array().conjugate() * xspec.array();
  }
  return out;
}

ImpactResult AverageHitSpectra(const ImpactDetection& detection,
                               const std::vector<const HitSpectra*>& spectra, double fs_hz,
                               const ImpactOptions& options, Estimator estimator,
                               Quantity response_quantity) {
  Require(spectra.size() == detection.hits.size(), "impact: one spectra entry per hit is needed");
  ImpactResult result;
  result.hits = detection.hits;
  result.spans = detection.spans;
  result.record_samples = detection.record_samples;
  result.pretrigger_samples = detection.pretrigger_samples;
  result.warnings = detection.warnings;
  std::size_t used = 0;
  bool doubles_used = false;
  std::ostringstream reasons;
  bool overridable = false;
  Eigen::Index responses = 0;
  for (std::size_t g = 0; g < spectra.size(); ++g) {
    if (detection.hits[g].used) {
      Require(spectra[g] != nullptr, "impact: spectra of a used hit are missing");
      responses = spectra[g]->gxx.cols();
    }
  }
  CrossSpectra sums = ZeroSpectra(detection.record_samples, responses, fs_hz);
  Eigen::VectorXd window_noise = Eigen::VectorXd::Zero(sums.gff.size());
  for (std::size_t g = 0; g < spectra.size(); ++g) {
    const Hit& hit = detection.hits[g];
    if (!hit.used) {
      reasons << " hit at " << hit.t_s << " s: " << hit.note << ";";
      overridable = overridable || !hit.truncated;
      continue;
    }
    doubles_used = doubles_used || hit.double_hit;
    const HitSpectra& s = *spectra[g];
    Require(s.gff.size() == sums.gff.size() && s.gxx.cols() == responses,
            "impact: spectra of another record length or channel count");
    sums.gff += s.gff;
    window_noise += s.window_noise;
    sums.gxx += s.gxx;
    sums.gfx += s.gfx;
    ++used;
  }
  if (used == 0) {
    throw InputError("no usable hit in the record:" + reasons.str() +
                     (overridable ? " (--keep-bad-hits uses double, clipped and weak hits anyway; "
                                    "--use-hits picks hits by number)"
                                  : ""));
  }
  sums.averages = used;
  const Eigen::VectorXd level_rel_var =
      LevelRelativeVariance(detection.force_noise_var, window_noise, sums.gff);
  const double scale =
      2.0 / (fs_hz * static_cast<double>(detection.record_samples) * static_cast<double>(used));
  sums.gff *= scale;
  sums.gxx *= scale;
  sums.gfx *= scale;
  result.frf = FrfFromSpectra(sums, estimator, response_quantity);
  constexpr double kForceFadingDb = 10.0;
  if (sums.freq_hz.size() > 2)
    MaskBelowResolution(sums.gxx, detection.response_rounding_var, detection.exp_window, scale,
                        used, options.response_resolution_factor,
                        ExcitedMaxHz(sums, kForceFadingDb), result.frf);
  result.frf.exp_window_tau_s = detection.exp_window_tau_s;
  result.frf.pretrigger_s = static_cast<double>(detection.pretrigger_samples) / fs_hz;
  result.frf.record_s = static_cast<double>(detection.record_samples) / fs_hz;
  if (estimator == Estimator::kH1) result.frf.level_rel_var = level_rel_var;
  const Eigen::Index lines = sums.freq_hz.size();
  result.usable_min_hz = sums.freq_hz[std::min<Eigen::Index>(1, lines - 1)];
  result.usable_max_hz = sums.freq_hz[lines - 1];
  if (lines > 2 && (doubles_used || options.force_band_db > 0.0)) {
    LimitToForceBand(sums, doubles_used ? options.force_dynamic_range_db : options.force_band_db,
                     doubles_used, result);
  }
  result.excited_max_hz = result.usable_max_hz;
  if (lines > 2 && options.force_excited_db > 0.0)
    result.excited_max_hz =
        std::min(result.usable_max_hz, ExcitedMaxHz(sums, options.force_excited_db));
  result.frf.force_band_min_hz = result.usable_min_hz;
  result.frf.force_band_max_hz = result.excited_max_hz;
  return result;
}

ImpactResult EstimateImpactFrf(const Eigen::Ref<const Eigen::VectorXd>& force,
                               const Eigen::Ref<const Eigen::MatrixXd>& responses, double fs_hz,
                               const ImpactOptions& options, Estimator estimator,
                               Quantity response_quantity) {
  const ImpactDetection detection = DetectImpactHits(force, responses, fs_hz, options);
  RealFft fft(detection.record_samples);
  std::vector<HitSpectra> kept(detection.hits.size());
  std::vector<const HitSpectra*> spectra(detection.hits.size(), nullptr);
  for (std::size_t g = 0; g < detection.hits.size(); ++g) {
    if (!detection.hits[g].used) continue;
    kept[g] = ImpactHitSpectra(force, responses, detection, g, fft);
    spectra[g] = &kept[g];
  }
  return AverageHitSpectra(detection, spectra, fs_hz, options, estimator, response_quantity);
}

}  // namespace vibid::ident
