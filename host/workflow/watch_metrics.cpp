// The watch's figures in Prometheus's text exposition format (0.0.4).
#include "vibid/workflow/watch_metrics.hpp"

#include <charconv>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

#include "vibid/common/error.hpp"

namespace vibid::workflow {
namespace {

using Labels = std::vector<std::pair<std::string, std::string>>;

/// A sample's value as the format writes it: the shortest decimal that reads back the same
/// double, NaN and ±Inf by the format's own spelling.
std::string Value(double v) {
  if (std::isnan(v)) return "NaN";
  if (std::isinf(v)) return v > 0 ? "+Inf" : "-Inf";
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

/// Families in the order of their first sample, each written once with all its samples (the
/// format wants a family's lines together, whichever watch they come from).
class Exposition {
 public:
  void Gauge(const char* name, const char* help, const Labels& labels, double value) {
    Add(name, help, "gauge", labels, value);
  }
  void Counter(const char* name, const char* help, const Labels& labels, double value) {
    Add(name, help, "counter", labels, value);
  }

  std::string Text() const {
    std::string out;
    for (const Family& f : families_) {
      out += "# HELP " + f.name + " " + f.help + "\n";
      out += "# TYPE " + f.name + " " + f.type + "\n";
      out += f.samples;
    }
    return out;
  }

 private:
  struct Family {
    std::string name, help, type, samples;
  };

  void Add(const char* name, const char* help, const char* type, const Labels& labels,
           double value) {
    Family* family = nullptr;
    for (Family& f : families_) family = f.name == name ? &f : family;
    if (family == nullptr) family = &families_.emplace_back(Family{name, help, type, {}});
    std::string line = name;
    if (!labels.empty()) {
      line += "{";
      for (std::size_t i = 0; i < labels.size(); ++i) {
        line += (i > 0 ? "," : "") + labels[i].first + "=\"" + MetricsLabelValue(labels[i].second) +
                "\"";
      }
      line += "}";
    }
    family->samples += line + " " + Value(value) + "\n";
  }

  std::vector<Family> families_;
};

Labels With(Labels labels, const char* name, int value) {
  labels.emplace_back(name, std::to_string(value));
  return labels;
}

Labels With(Labels labels, const char* name, const std::string& value) {
  labels.emplace_back(name, value);
  return labels;
}

double Hz(double omega_rad_s) { return omega_rad_s / (2.0 * std::numbers::pi); }

/// Every figure of one watch: one line each.
void Expose(const WatchFigures& w, Exposition& e) {
  const Labels rig{{"rig", w.rig}};
  e.Gauge("vibid_watch_running", "1 while the watch feeds blocks, 0 once it ended", rig,
          w.running ? 1 : 0);
  e.Gauge("vibid_watch_false_alarms_per_hour",
          "False alarms per hour of an unchanged rig the watch was asked for", rig,
          w.options.false_alarm_per_hour);
  e.Gauge("vibid_watch_block_length_seconds", "Seconds per block", rig, w.options.block_s);
  e.Gauge("vibid_watch_window_length_blocks", "Blocks per window of the accumulated test", rig,
          w.options.window_blocks);
  e.Gauge("vibid_watch_sequential_length_blocks", "Longest onset of the sequential test, blocks",
          rig, w.options.sequential_blocks);
  e.Gauge("vibid_watch_reference_ready", "1 once the reference is built", rig, w.reference ? 1 : 0);
  e.Counter("vibid_watch_blocks_total", "Blocks watched since the reference", rig,
            static_cast<double>(w.blocks));
  if (w.reference) {
    const WatchReference& r = *w.reference;
    e.Gauge("vibid_watch_reference_seconds", "Seconds of the reference", rig, r.seconds);
    e.Gauge("vibid_watch_test_order", "Model order of the subspace test", rig, r.order);
    // The rate this reference gives, its 95 % band (docs/watch.md: the rate of the reference a
    // user has).
    e.Gauge("vibid_watch_reference_false_alarms_per_hour",
            "False alarms per hour this reference gives, 95 % band", With(rig, "bound", "low"),
            r.false_alarms_per_hour_low);
    e.Gauge("vibid_watch_reference_false_alarms_per_hour",
            "False alarms per hour this reference gives, 95 % band", With(rig, "bound", "high"),
            r.false_alarms_per_hour_high);
    e.Gauge("vibid_watch_reference_sequential_false_alarms_per_hour",
            "False alarms per hour this reference gives the sequential test, 95 % band",
            With(rig, "bound", "low"), r.sequential_false_alarms_per_hour_low);
    e.Gauge("vibid_watch_reference_sequential_false_alarms_per_hour",
            "False alarms per hour this reference gives the sequential test, 95 % band",
            With(rig, "bound", "high"), r.sequential_false_alarms_per_hour_high);
    for (std::size_t i = 0; i < r.modes.size(); ++i) {
      const Labels m = With(rig, "mode", static_cast<int>(i) + 1);
      e.Gauge("vibid_watch_reference_mode_frequency_hertz", "The reference's mode frequency", m,
              Hz(r.modes[i].omega_rad_s));
      e.Gauge("vibid_watch_reference_mode_frequency_ci95_hertz",
              "95 % half-width of the reference's mode frequency", m,
              Hz(r.modes[i].omega_ci95_rad_s));
      e.Gauge("vibid_watch_reference_mode_damping_ratio", "The reference's mode damping ratio", m,
              r.modes[i].zeta);
    }
  }
  if (!w.last) return;
  const WatchBlock& b = *w.last;
  e.Gauge("vibid_watch_time_seconds", "End of the last block, seconds from the watch's start", rig,
          b.t_s);
  if (w.last_block_unix_s) {
    e.Gauge("vibid_watch_last_block_timestamp_seconds", "Unix time the last block came", rig,
            *w.last_block_unix_s);
  }
  for (std::size_t i = 0; i < b.modes.size(); ++i) {
    const Labels m = With(rig, "mode", static_cast<int>(i) + 1);
    e.Gauge("vibid_watch_mode_frequency_hertz", "Mode frequency over the last modes span", m,
            Hz(b.modes[i].omega_rad_s));
    e.Gauge("vibid_watch_mode_frequency_ci95_hertz", "95 % half-width of the mode frequency", m,
            Hz(b.modes[i].omega_ci95_rad_s));
    e.Gauge("vibid_watch_mode_damping_ratio", "Mode damping ratio over the last modes span", m,
            b.modes[i].zeta);
    e.Gauge("vibid_watch_mode_damping_ratio_ci95", "95 % half-width of the mode damping ratio", m,
            b.modes[i].zeta_ci95);
  }
  if (b.moved) {
    const Labels m = With(rig, "mode", b.moved->mode);
    e.Gauge("vibid_watch_moved_significance",
            "Change over its 95 % half-width of the quantity that moved most (ω, ζ or shape)",
            With(m, "quantity", b.moved->quantity), b.moved->significance);
    e.Gauge("vibid_watch_moved_damping_ratio_change",
            "Damping ratio change of the mode that moved most against the reference", m,
            b.moved->zeta_change);
    e.Gauge("vibid_watch_moved_damping_ratio_change_ci95",
            "95 % half-width of that damping ratio change", m, b.moved->zeta_ci95);
    e.Gauge("vibid_watch_moved_frequency_change_ratio",
            "Relative frequency change of the mode that moved most against the reference", m,
            b.moved->relative);
    e.Gauge("vibid_watch_moved_frequency_change_ci95_ratio",
            "95 % half-width of that change, relative to the reference's frequency", m,
            b.moved->omega_ref_rad_s > 0 ? b.moved->ci95_rad_s / b.moved->omega_ref_rad_s
                                         : std::numeric_limits<double>::quiet_NaN());
  }
  e.Gauge("vibid_watch_block_statistic", "The last block's subspace T2", rig, b.statistic);
  // One block's T2 is heavier-tailed than F (docs/watch.md): its F quantile is exposed under that
  // name, not as a threshold an alert could be written against.
  e.Gauge("vibid_watch_block_f_quantile",
          "The F quantile at the block's rate beside the block T2 (not a calibrated threshold)",
          rig, b.f_quantile);
  e.Gauge("vibid_watch_block_over", "1 when the last block's T2 is over its F quantile", rig,
          b.block_over ? 1 : 0);
  e.Gauge("vibid_watch_window_statistic", "T2 of the window's blocks so far", rig,
          b.accumulated_statistic);
  e.Gauge("vibid_watch_window_threshold", "The full window's threshold", rig,
          b.accumulated_threshold);
  e.Gauge("vibid_watch_window_blocks", "Blocks in the window so far", rig, b.window_count);
  e.Gauge("vibid_watch_window_tested",
          "1 when the window is full and its T2 was tested against the threshold", rig,
          b.window_count == b.window_blocks ? 1 : 0);
  e.Gauge("vibid_watch_window_alarm", "1 when the last full window alarmed", rig,
          b.window_alarm ? 1 : 0);
  e.Gauge("vibid_watch_sequential_statistic", "The sequential test's GLR statistic g", rig,
          b.sequential_statistic);
  e.Gauge("vibid_watch_sequential_threshold", "The sequential test's threshold h", rig,
          b.sequential_threshold);
  e.Gauge("vibid_watch_sequential_onset_blocks",
          "Blocks back to the onset that maximised the sequential statistic", rig,
          b.sequential_onset_blocks);
  e.Gauge("vibid_watch_sequential_alarm", "1 when the last block's sequential test alarmed", rig,
          b.sequential_alarm ? 1 : 0);
  e.Gauge("vibid_watch_alarm", "1 from the watch's first alarm on (latched)", rig,
          b.first_alarm_t_s ? 1 : 0);
  if (b.first_alarm_t_s) {
    e.Gauge("vibid_watch_first_alarm_time_seconds",
            "When the first alarm came, seconds from the watch's start", rig, *b.first_alarm_t_s);
  }
  e.Gauge("vibid_watch_analysis_seconds", "Wall time of the last block's analysis", rig,
          b.analysis_ms / 1000.0);
  if (b.board) {
    e.Gauge("vibid_board_model_stale", "The board's model-stale flag (latched once tripped)", rig,
            b.board->stale ? 1 : 0);
    e.Gauge("vibid_board_model_statistic", "The board's CUSUM statistic g on its residual", rig,
            b.board->statistic);
    if (b.board->threshold > 0) {
      e.Gauge("vibid_board_model_threshold", "The board's CUSUM threshold h", rig,
              b.board->threshold);
    }
    if (b.board->stale_since_t_s) {
      e.Gauge("vibid_board_model_stale_since_seconds",
              "When the board's flag was first seen, seconds from the watch's start", rig,
              *b.board->stale_since_t_s);
    }
  }
}

}  // namespace

std::string MetricsLabelValue(const std::string& value) {
  std::string out;
  out.reserve(value.size());
  for (const char c : value) {
    if (c == '\\') {
      out += "\\\\";
    } else if (c == '"') {
      out += "\\\"";
    } else if (c == '\n') {
      out += "\\n";
    } else {
      out += c;
    }
  }
  return out;
}

std::string WatchMetricsText(const std::vector<WatchFigures>& watches) {
  Exposition e;
  for (const WatchFigures& w : watches) Expose(w, e);
  return e.Text();
}

WatchMetrics::WatchMetrics(std::string rig) {
  Require(!rig.empty(), "the rig's name for the metrics is empty: name it (--metrics-rig NAME)");
  figures_.rig = std::move(rig);
}

void WatchMetrics::Start(const WatchOptions& options) {
  std::lock_guard l(mutex_);
  WatchFigures fresh;
  fresh.rig = figures_.rig;
  fresh.options = options;
  fresh.running = true;
  figures_ = std::move(fresh);
}

void WatchMetrics::Reference(const WatchReference& reference) {
  std::lock_guard l(mutex_);
  figures_.reference = reference;
}

void WatchMetrics::Block(const WatchBlock& block) {
  const double now_s =
      std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  std::lock_guard l(mutex_);
  figures_.last = block;
  figures_.blocks += 1;
  figures_.last_block_unix_s = now_s;
}

void WatchMetrics::End() {
  std::lock_guard l(mutex_);
  figures_.running = false;
}

std::string WatchMetrics::Text() const { return WatchMetricsText({Figures()}); }

WatchFigures WatchMetrics::Figures() const {
  std::lock_guard l(mutex_);
  return figures_;
}

}  // namespace vibid::workflow
