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

}  // namespace

nlohmann::json WatchBlockJson(const WatchBlock& b) {
  nlohmann::json moved = nullptr;
  if (b.moved) {
    moved = {{"mode", b.moved->mode},
             {"omega_ref_rad_s", b.moved->omega_ref_rad_s},
             {"omega_rad_s", b.moved->omega_rad_s},
             {"change_rad_s", b.moved->change_rad_s},
             {"ci95_rad_s", b.moved->ci95_rad_s},
             {"relative", b.moved->relative}};
  }
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
            {"alarm", b.window_alarm}}},
          {"first_alarm_t_s", first},
          {"moved", moved},
          {"board", board},
          {"modes_message", b.modes_message},
          {"analysis_ms", b.analysis_ms}};
}

nlohmann::json WatchReferenceJson(const WatchReference& r) {
  return {{"seconds", r.seconds},
          {"modes", ModesJson(r.modes)},
          {"order", r.order},
          {"dof", r.dof},
          {"reference_blocks", r.reference_blocks},
          {"block_f_quantile", r.block_f_quantile},
          {"window_threshold", r.window_threshold},
          {"false_alarms_per_hour_95", {r.false_alarms_per_hour_low, r.false_alarms_per_hour_high}},
          {"false_alarms_per_hour_mean", r.false_alarms_per_hour_mean},
          {"advised_reference_s", r.advised_reference_s},
          {"analysis_ms", r.analysis_ms}};
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
  std::snprintf(line, sizeof line, " | T² %.1f | window %.1f/%.1f (%d/%d)", b.statistic,
                b.accumulated_statistic, b.accumulated_threshold, b.window_count, b.window_blocks);
  out += line;
  if (b.moved) {
    std::snprintf(line, sizeof line, " | mode %d %+.2f±%.2f %%", b.moved->mode,
                  100.0 * b.moved->relative,
                  100.0 * b.moved->ci95_rad_s / b.moved->omega_ref_rad_s);
    out += line;
  }
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
