// The watch's blocks as JSON lines and as one line of text each.
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "vibid/workflow/watch_session.hpp"

namespace vibid::workflow {

namespace {

nlohmann::json ModesJson(const std::vector<WatchMode>& modes) {
  nlohmann::json out = nlohmann::json::array();
  for (const WatchMode& m : modes) {
    out.push_back({{"omega_rad_s", m.omega_rad_s},
                   {"zeta", m.zeta},
                   {"ci95", {{"omega_rad_s", m.omega_ci95_rad_s}, {"zeta", m.zeta_ci95}}}});
  }
  return out;
}

// "mode 1 ζ +35.2±21.0 % (1.7× its interval)": the quantity that moved most, its change over the
// reference's value (relative for ω and ζ; for the shape the entry that moved most, in units of
// the shape's largest entry, with the MAC), and the change over its combined 95 % interval.
std::string WatchMoveText(const WatchMove& m) {
  char line[160];
  if (m.quantity == "zeta") {
    std::snprintf(line, sizeof line, "mode %d ζ %+.1f±%.1f %% (%.1f× its interval)", m.mode,
                  100.0 * m.zeta_change / m.zeta_ref, 100.0 * m.zeta_ci95 / m.zeta_ref,
                  m.significance);
  } else if (m.quantity == "shape") {
    std::snprintf(line, sizeof line,
                  "mode %d shape entry %d %+.3f±%.3f, MAC %.4f (%.1f× its interval)", m.mode,
                  m.shape_entry + 1, m.shape_change, m.shape_ci95, m.mac, m.significance);
  } else {
    std::snprintf(line, sizeof line, "mode %d ω %+.2f±%.2f %% (%.1f× its interval)", m.mode,
                  100.0 * m.relative, 100.0 * m.ci95_rad_s / m.omega_ref_rad_s, m.significance);
  }
  return line;
}

nlohmann::json MovedJson(const WatchMove& m) {
  nlohmann::json shape = nullptr;
  if (m.shape_entry >= 0) {
    shape = {{"entry", m.shape_entry + 1},
             {"change", m.shape_change},
             {"ci95", m.shape_ci95},
             {"significance", m.shape_significance},
             {"mac", m.mac}};
  }
  return {{"mode", m.mode},
          {"quantity", m.quantity},
          {"significance", m.significance},
          {"omega_ref_rad_s", m.omega_ref_rad_s},
          {"omega_rad_s", m.omega_rad_s},
          {"change_rad_s", m.change_rad_s},
          {"ci95_rad_s", m.ci95_rad_s},
          {"relative", m.relative},
          {"omega_significance", m.omega_significance},
          {"zeta",
           {{"ref", m.zeta_ref},
            {"now", m.zeta},
            {"change", m.zeta_change},
            {"ci95", m.zeta_ci95},
            {"significance", m.zeta_significance}}},
          {"shape", shape}};
}

}  // namespace

nlohmann::json WatchBlockJson(const WatchBlock& b) {
  nlohmann::json moved = nullptr;
  if (b.moved) moved = MovedJson(*b.moved);
  nlohmann::json first = nullptr;
  if (b.first_alarm_t_s) first = *b.first_alarm_t_s;
  nlohmann::json board = nullptr;
  if (b.board) {
    board = {{"stale", b.board->stale},
             {"statistic", b.board->statistic},
             {"threshold", b.board->threshold},
             {"stale_since_t_s", nullptr}};
    if (b.board->stale_since_t_s) board["stale_since_t_s"] = *b.board->stale_since_t_s;
  }
  return {{"t_s", b.t_s},
          {"block", b.index},
          {"modes", ModesJson(b.modes)},
          {"statistic", b.statistic},
          {"f_quantile", b.f_quantile},
          {"alarm", b.alarm},
          {"block_over", b.block_over},
          {"accumulated",
           {{"statistic", b.accumulated_statistic},
            {"threshold", b.accumulated_threshold},
            {"blocks", b.window_count},
            {"window_blocks", b.window_blocks},
            {"tested", b.window_count == b.window_blocks},
            {"alarm", b.window_alarm}}},
          {"sequential",
           {{"statistic", b.sequential_statistic},
            {"threshold", b.sequential_threshold},
            {"onset_blocks", b.sequential_onset_blocks},
            {"blocks", b.sequential_blocks},
            {"alarm", b.sequential_alarm}}},
          {"first_alarm_t_s", first},
          {"moved", moved},
          {"board", board},
          {"modes_message", b.modes_message},
          {"analysis_ms", b.analysis_ms}};
}

nlohmann::json WatchReferenceJson(const WatchReference& r) {
  return {{"source", r.source},
          {"span", {{"from_t_s", r.from_t_s}, {"to_t_s", r.to_t_s}}},
          {"seconds", r.seconds},
          {"modes", ModesJson(r.modes)},
          {"order", r.order},
          {"dof", r.dof},
          {"reference_blocks", r.reference_blocks},
          {"block_f_quantile", r.block_f_quantile},
          {"window_threshold", r.window_threshold},
          {"false_alarms_per_hour_95", {r.false_alarms_per_hour_low, r.false_alarms_per_hour_high}},
          {"false_alarms_per_hour_mean", r.false_alarms_per_hour_mean},
          {"advised_reference_s", r.advised_reference_s},
          {"sequential_threshold", r.sequential_threshold},
          {"sequential_exact_threshold", r.sequential_exact_threshold},
          {"sequential_false_alarms_per_hour_95",
           {r.sequential_false_alarms_per_hour_low, r.sequential_false_alarms_per_hour_high}},
          {"sequential_false_alarms_per_hour_mean", r.sequential_false_alarms_per_hour_mean},
          {"analysis_ms", r.analysis_ms}};
}

nlohmann::json WatchOptionsJson(const WatchOptions& o) {
  return {{"fs_hz", o.fs_hz},
          {"channels", o.channels},
          {"reference_s", o.reference_s},
          {"block_s", o.block_s},
          {"window_blocks", o.window_blocks},
          {"false_alarm_per_hour", o.false_alarm_per_hour},
          {"block_false_alarm", o.BlockFalseAlarm()},
          {"window_false_alarm", o.WindowFalseAlarm()},
          {"sequential_blocks", o.sequential_blocks},
          {"fmax_hz", o.fmax_hz},
          {"modes_s", o.modes_s},
          {"order", o.order},
          {"null_space_share", o.null_space_share}};
}

nlohmann::json WatchHeaderJson(const WatchSession& s) {
  return {{"header", "vibid watch"},
          {"version", 1},
          {"options", WatchOptionsJson(s.options())},
          {"reference", WatchReferenceJson(s.reference())}};
}

std::string WatchBlockText(const WatchBlock& b) {
  char line[160];
  std::snprintf(line, sizeof line, "t %8.1f s ", b.t_s);
  std::string out = line;
  if (b.modes.empty()) {
    out += " modes: -";
  } else {
    for (const WatchMode& m : b.modes) {
      const double hz = m.omega_rad_s / (2.0 * std::numbers::pi);
      std::snprintf(line, sizeof line, " %.3f±%.3f Hz ζ %.2f %%", hz,
                    m.omega_ci95_rad_s / (2.0 * std::numbers::pi), 100.0 * m.zeta);
      out += line;
    }
  }
  std::snprintf(line, sizeof line, " | T² %.1f", b.statistic);
  out += line;
  // A window is one test when full; before that its statistic has no threshold of its own, so
  // only its count is shown.
  if (b.window_count == b.window_blocks) {
    std::snprintf(line, sizeof line, " | window %.1f/%.1f (%d blocks)", b.accumulated_statistic,
                  b.accumulated_threshold, b.window_blocks);
  } else {
    std::snprintf(line, sizeof line, " | window %d/%d blocks, tested when full", b.window_count,
                  b.window_blocks);
  }
  out += line;
  // The sequential test decides at every block: its g against h, and the onset that maximised g
  // (none while it holds fewer blocks than its shortest onset).
  if (b.sequential_onset_blocks == 0) {
    std::snprintf(line, sizeof line, " | seq -/%.1f", b.sequential_threshold);
  } else {
    std::snprintf(line, sizeof line, " | seq %.1f/%.1f (k %d)", b.sequential_statistic,
                  b.sequential_threshold, b.sequential_onset_blocks);
  }
  out += line;
  if (b.moved) out += " | " + WatchMoveText(*b.moved);
  if (b.board) {
    if (b.board->stale) {
      std::snprintf(line, sizeof line, " | board STALE since %.1f s",
                    b.board->stale_since_t_s.value_or(b.t_s));
    } else if (b.board->threshold > 0.0) {
      std::snprintf(line, sizeof line, " | board g %.2f/%.2f", b.board->statistic,
                    b.board->threshold);
    } else {
      std::snprintf(line, sizeof line, " | board g %.2f", b.board->statistic);
    }
    out += line;
  }
  if (b.alarm) {
    out += " | ALARM";
  } else if (b.first_alarm_t_s) {
    std::snprintf(line, sizeof line, " | alarmed at %.1f s", *b.first_alarm_t_s);
    out += line;
  } else {
    out += " | ok";
  }
  return out;
}

}  // namespace vibid::workflow
