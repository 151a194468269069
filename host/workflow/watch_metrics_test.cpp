// The watch's figures in Prometheus's text format, against the format's definition (Prometheus,
// "Exposition formats", text format 0.0.4): # HELP and # TYPE once per family before its samples,
// a family's samples together, label values with \\, \" and \n escaped, NaN and ±Inf spelled so.
#include "vibid/workflow/watch_metrics.hpp"

#include <cmath>
#include <numbers>
#include <sstream>

#include <gtest/gtest.h>

#include "vibid/common/error.hpp"

namespace vibid::workflow {
namespace {

constexpr double kPi = std::numbers::pi;

WatchFigures Watch(const std::string& rig) {
  WatchFigures w;
  w.rig = rig;
  w.options.false_alarm_per_hour = 0.01;
  w.options.block_s = 10.0;
  w.options.window_blocks = 60;
  w.running = true;
  return w;
}

bool Has(const std::string& text, const std::string& line) {
  return text.find("\n" + line + "\n") != std::string::npos || text.rfind(line + "\n", 0) == 0;
}

TEST(WatchMetrics, AWatchBeforeItsReferenceShowsItsOptionsOnly) {
  // Written out by hand from the format's grammar.
  EXPECT_EQ(WatchMetricsText({Watch("rig-a")}),
            "# HELP vibid_watch_running 1 while the watch feeds blocks, 0 once it ended\n"
            "# TYPE vibid_watch_running gauge\n"
            "vibid_watch_running{rig=\"rig-a\"} 1\n"
            "# HELP vibid_watch_false_alarms_per_hour False alarms per hour of an unchanged rig "
            "the watch was asked for\n"
            "# TYPE vibid_watch_false_alarms_per_hour gauge\n"
            "vibid_watch_false_alarms_per_hour{rig=\"rig-a\"} 0.01\n"
            "# HELP vibid_watch_block_length_seconds Seconds per block\n"
            "# TYPE vibid_watch_block_length_seconds gauge\n"
            "vibid_watch_block_length_seconds{rig=\"rig-a\"} 10\n"
            "# HELP vibid_watch_window_length_blocks Blocks per window of the accumulated test\n"
            "# TYPE vibid_watch_window_length_blocks gauge\n"
            "vibid_watch_window_length_blocks{rig=\"rig-a\"} 60\n"
            "# HELP vibid_watch_sequential_length_blocks Longest onset of the sequential test, "
            "blocks\n"
            "# TYPE vibid_watch_sequential_length_blocks gauge\n"
            "vibid_watch_sequential_length_blocks{rig=\"rig-a\"} 60\n"
            "# HELP vibid_watch_reference_ready 1 once the reference is built\n"
            "# TYPE vibid_watch_reference_ready gauge\n"
            "vibid_watch_reference_ready{rig=\"rig-a\"} 0\n"
            "# HELP vibid_watch_blocks_total Blocks watched since the reference\n"
            "# TYPE vibid_watch_blocks_total counter\n"
            "vibid_watch_blocks_total{rig=\"rig-a\"} 0\n");
}

TEST(WatchMetrics, EveryFigureOfABlockInBaseUnits) {
  WatchFigures w = Watch("rig-a");
  WatchReference r;
  r.seconds = 1800;
  r.order = 4;
  r.false_alarms_per_hour_low = 0.00125;
  r.false_alarms_per_hour_high = 0.01;
  // ω = 2π·4 rad/s is 4 Hz exactly in binary (a power-of-two scaling of the same π).
  r.modes = {{2 * kPi * 4, 0.0175, 2 * kPi * 0.25, 0.002}};
  w.reference = r;
  WatchBlock b;
  b.t_s = 2400;
  b.modes = {{2 * kPi * 4, 0.02, 2 * kPi * 0.5, 0.004}, {2 * kPi * 8, 0.05, 2 * kPi * 1, 0.01}};
  b.statistic = 19.5;
  b.f_quantile = 41.25;
  b.accumulated_statistic = 30.5;
  b.accumulated_threshold = 28;
  b.window_count = 60;
  b.window_blocks = 60;
  b.window_alarm = true;
  b.alarm = true;
  b.first_alarm_t_s = 2400;
  WatchMove moved;
  moved.mode = 1;
  moved.quantity = "zeta";
  moved.significance = 2.5;
  moved.omega_ref_rad_s = 2 * kPi * 4;
  moved.omega_rad_s = 2 * kPi * 3.96;
  moved.change_rad_s = -2 * kPi * 0.04;
  moved.ci95_rad_s = 2 * kPi * 0.02;
  moved.relative = -0.01;
  moved.zeta_change = 0.0025;
  moved.zeta_ci95 = 0.001;
  b.moved = moved;
  b.board = WatchBoardModel{true, 12.5, 10, 2300};
  b.analysis_ms = 250;
  w.last = b;
  w.blocks = 60;
  w.last_block_unix_s = 1.8e9;
  const std::string t = WatchMetricsText({w});
  EXPECT_TRUE(Has(t, "vibid_watch_reference_ready{rig=\"rig-a\"} 1"));
  EXPECT_TRUE(Has(t, "vibid_watch_blocks_total{rig=\"rig-a\"} 60"));
  EXPECT_TRUE(Has(t, "vibid_watch_reference_seconds{rig=\"rig-a\"} 1800"));
  EXPECT_TRUE(Has(t, "vibid_watch_test_order{rig=\"rig-a\"} 4"));
  EXPECT_TRUE(Has(t, "vibid_watch_reference_mode_frequency_hertz{rig=\"rig-a\",mode=\"1\"} 4"));
  EXPECT_TRUE(
      Has(t, "vibid_watch_reference_mode_frequency_ci95_hertz{rig=\"rig-a\",mode=\"1\"} 0.25"));
  EXPECT_TRUE(Has(t, "vibid_watch_reference_mode_damping_ratio{rig=\"rig-a\",mode=\"1\"} 0.0175"));
  EXPECT_TRUE(Has(t, "vibid_watch_time_seconds{rig=\"rig-a\"} 2400"));
  // The shortest decimal that reads back the same double: here in exponent form, which the
  // format takes (Go's ParseFloat).
  EXPECT_TRUE(Has(t, "vibid_watch_last_block_timestamp_seconds{rig=\"rig-a\"} 1.8e+09"));
  EXPECT_TRUE(Has(t, "vibid_watch_mode_frequency_hertz{rig=\"rig-a\",mode=\"1\"} 4"));
  EXPECT_TRUE(Has(t, "vibid_watch_mode_frequency_hertz{rig=\"rig-a\",mode=\"2\"} 8"));
  EXPECT_TRUE(Has(t, "vibid_watch_mode_frequency_ci95_hertz{rig=\"rig-a\",mode=\"2\"} 1"));
  EXPECT_TRUE(Has(t, "vibid_watch_mode_damping_ratio{rig=\"rig-a\",mode=\"2\"} 0.05"));
  EXPECT_TRUE(Has(t, "vibid_watch_mode_damping_ratio_ci95{rig=\"rig-a\",mode=\"1\"} 0.004"));
  EXPECT_TRUE(Has(t, "vibid_watch_moved_frequency_change_ratio{rig=\"rig-a\",mode=\"1\"} -0.01"));
  // 0.02 Hz of a 4 Hz mode: 0.005.
  EXPECT_TRUE(
      Has(t, "vibid_watch_moved_frequency_change_ci95_ratio{rig=\"rig-a\",mode=\"1\"} 0.005"));
  EXPECT_TRUE(Has(t, "vibid_watch_block_statistic{rig=\"rig-a\"} 19.5"));
  EXPECT_TRUE(Has(t, "vibid_watch_block_f_quantile{rig=\"rig-a\"} 41.25"));
  EXPECT_FALSE(Has(t, "vibid_watch_block_threshold"));  // not calibrated: no threshold by name
  EXPECT_TRUE(Has(t, "vibid_watch_window_tested{rig=\"rig-a\"} 1"));
  EXPECT_TRUE(
      Has(t, "vibid_watch_moved_significance{rig=\"rig-a\",mode=\"1\",quantity=\"zeta\"} 2.5"));
  EXPECT_TRUE(Has(t, "vibid_watch_moved_damping_ratio_change{rig=\"rig-a\",mode=\"1\"} 0.0025"));
  EXPECT_TRUE(
      Has(t, "vibid_watch_reference_false_alarms_per_hour{rig=\"rig-a\",bound=\"low\"} 0.00125"));
  EXPECT_TRUE(
      Has(t, "vibid_watch_reference_false_alarms_per_hour{rig=\"rig-a\",bound=\"high\"} 0.01"));
  EXPECT_TRUE(Has(t, "vibid_watch_block_over{rig=\"rig-a\"} 0"));
  EXPECT_TRUE(Has(t, "vibid_watch_window_statistic{rig=\"rig-a\"} 30.5"));
  EXPECT_TRUE(Has(t, "vibid_watch_window_threshold{rig=\"rig-a\"} 28"));
  EXPECT_TRUE(Has(t, "vibid_watch_window_blocks{rig=\"rig-a\"} 60"));
  EXPECT_TRUE(Has(t, "vibid_watch_window_alarm{rig=\"rig-a\"} 1"));
  EXPECT_TRUE(Has(t, "vibid_watch_alarm{rig=\"rig-a\"} 1"));
  EXPECT_TRUE(Has(t, "vibid_watch_first_alarm_time_seconds{rig=\"rig-a\"} 2400"));
  EXPECT_TRUE(Has(t, "vibid_watch_analysis_seconds{rig=\"rig-a\"} 0.25"));
  EXPECT_TRUE(Has(t, "vibid_board_model_stale{rig=\"rig-a\"} 1"));
  EXPECT_TRUE(Has(t, "vibid_board_model_statistic{rig=\"rig-a\"} 12.5"));
  EXPECT_TRUE(Has(t, "vibid_board_model_threshold{rig=\"rig-a\"} 10"));
  EXPECT_TRUE(Has(t, "vibid_board_model_stale_since_seconds{rig=\"rig-a\"} 2300"));
  EXPECT_TRUE(Has(t, "# TYPE vibid_board_model_stale gauge"));

  // Without the board's columns, its families are absent, not 0; before an alarm, its time too.
  w.last->board.reset();
  w.last->first_alarm_t_s.reset();
  const std::string u = WatchMetricsText({w});
  EXPECT_EQ(u.find("vibid_board_"), std::string::npos);
  EXPECT_EQ(u.find("vibid_watch_first_alarm_time_seconds"), std::string::npos);
  EXPECT_TRUE(Has(u, "vibid_watch_alarm{rig=\"rig-a\"} 0"));
}

TEST(WatchMetrics, TwoWatchesShareEachFamilysHeadAndTheirSamplesStayTogether) {
  const std::string t = WatchMetricsText({Watch("a"), Watch("b")});
  // The format: a family's # HELP and # TYPE once, its samples consecutive.
  std::istringstream lines(t);
  std::string line, family;
  std::vector<std::string> seen;
  int heads = 0;
  while (std::getline(lines, line)) {
    if (line.rfind("# TYPE ", 0) == 0) {
      family = line.substr(7, line.find(' ', 7) - 7);
      for (const std::string& s : seen) EXPECT_NE(s, family) << "family twice: " << family;
      seen.push_back(family);
      ++heads;
    } else if (line[0] != '#') {
      EXPECT_EQ(line.rfind(family + "{", 0), 0u) << line << " outside " << family;
    }
  }
  EXPECT_EQ(heads, 7);
  EXPECT_TRUE(Has(t, "vibid_watch_running{rig=\"a\"} 1\nvibid_watch_running{rig=\"b\"} 1"));
}

TEST(WatchMetrics, LabelValuesAndSpecialValuesAreWrittenAsTheFormatSpellsThem) {
  EXPECT_EQ(MetricsLabelValue(R"(a\b"c)"
                              "\n"),
            R"(a\\b\"c\n)");
  WatchFigures w = Watch("line\n\"two\"");
  w.options.false_alarm_per_hour = std::numeric_limits<double>::infinity();
  w.options.block_s = std::nan("");
  const std::string t = WatchMetricsText({w});
  EXPECT_TRUE(Has(t, R"(vibid_watch_false_alarms_per_hour{rig="line\n\"two\""} +Inf)"));
  EXPECT_TRUE(Has(t, R"(vibid_watch_block_length_seconds{rig="line\n\"two\""} NaN)"));
}

TEST(WatchMetrics, KeepsTheLastBlockAndRefusesAnUnnamedRig) {
  EXPECT_THROW(WatchMetrics(""), InputError);
  WatchMetrics m("rig-a");
  WatchOptions o;
  o.block_s = 5;
  m.Start(o);
  WatchBlock b;
  b.t_s = 235;
  m.Block(b);
  b.t_s = 240;
  m.Block(b);
  EXPECT_EQ(m.Figures().blocks, 2);
  EXPECT_TRUE(Has(m.Text(), "vibid_watch_time_seconds{rig=\"rig-a\"} 240"));
  EXPECT_TRUE(Has(m.Text(), "vibid_watch_running{rig=\"rig-a\"} 1"));
  m.End();
  EXPECT_TRUE(Has(m.Text(), "vibid_watch_running{rig=\"rig-a\"} 0"));
  // A new watch drops the last one's figures.
  m.Start(o);
  EXPECT_EQ(m.Text().find("vibid_watch_time_seconds"), std::string::npos);
}

}  // namespace
}  // namespace vibid::workflow
