// The live hammer test against the CLI's library path: the session's verdicts on a synthetic
// board recording fed in random blocks, and its FRF and modes against EstimateFromRecording and
// IdentifyModes on the recording it saved, with the hit list it saved (bit for bit).
#include "vibid/workflow/hammer_session.hpp"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "testing/board_hammer_test.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/json_file.hpp"
#include "vibid/device/log_table.hpp"
#include "vibid/ident/frf_io.hpp"
#include "vibid/workflow/result_json.hpp"

namespace vibid::workflow {
namespace {

std::string TempDir(const std::string& tag) {
  const std::filesystem::path p =
      std::filesystem::temp_directory_path() /
      ("vibid-hammer-" + tag + "-" +
       std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "-" +
       std::to_string(reinterpret_cast<std::uintptr_t>(&tag)));
  std::filesystem::remove_all(p);
  std::filesystem::create_directories(p);
  return p.string();
}

std::string FileText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void ExpectSameFrf(const ident::Frf& a, const ident::Frf& b) {
  ASSERT_EQ(a.lines(), b.lines());
  ASSERT_EQ(a.responses(), b.responses());
  EXPECT_TRUE(a.freq_hz.cwiseEqual(b.freq_hz).all());
  EXPECT_TRUE(a.h.cwiseEqual(b.h).all());
  EXPECT_TRUE(a.coherence.cwiseEqual(b.coherence).all());
  EXPECT_TRUE(a.level_rel_var.size() == b.level_rel_var.size() &&
              a.level_rel_var.cwiseEqual(b.level_rel_var).all());
  EXPECT_EQ(a.averages, b.averages);
  EXPECT_EQ(a.exp_window_tau_s, b.exp_window_tau_s);
  EXPECT_EQ(a.pretrigger_s, b.pretrigger_s);
  EXPECT_EQ(a.record_s, b.record_s);
}

const std::vector<std::string> kVerdicts = {"ok", "ok",       "double hit", "ok", "clipped",
                                            "ok", "too weak", "ok",         "ok", "truncated"};

// Feeds the records in random blocks and checks that each hit is judged in the block that
// completes its record (pretrigger + record from the record's start); returns the update times.
struct Timing {
  double mean_ms = 0.0;
  double worst_ms = 0.0;
  double worst_modes_ms = 0.0;
};
Timing FeedAndWatch(HammerSession& session, const std::vector<wire::LogRecord>& records,
                    std::size_t record, std::uint64_t seed) {
  std::size_t judged = 0;
  Timing t;
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::size_t> size(1, 700);
  for (std::size_t at = 0; at < records.size();) {
    const std::size_t n = std::min(size(rng), records.size() - at);
    session.Feed(std::span<const wire::LogRecord>(records.data() + at, n));
    at += n;
    const HammerSnapshot s = session.Snapshot();
    if (s.hits.size() == judged) continue;
    EXPECT_EQ(s.hits.size(), judged + 1);
    // The automatic pretrigger: 1/64 of the record (ident::ImpactOptions::pretrigger_s).
    const auto trigger = static_cast<std::size_t>(std::llround(s.hits.back().t_s * s.fs_hz));
    const std::size_t complete = trigger - record / 64 + record;
    EXPECT_GE(at, complete) << "hit " << s.hits.size();
    EXPECT_LT(at - n, complete) << "hit " << s.hits.size();
    judged = s.hits.size();
    t.worst_ms = std::max(t.worst_ms, s.last_update_ms);
    t.mean_ms += s.last_update_ms;
    t.worst_modes_ms = std::max(t.worst_modes_ms, s.last_modes_ms);
  }
  t.mean_ms /= static_cast<double>(std::max<std::size_t>(judged, 1));
  return t;
}

// Each hit judged as soon as its 2 s record is complete, the last one pending until the
// acquisition ends; the time each judgement takes with the FRF and modes updated (3 channels at
// 5 kHz).
TEST(HammerSession, JudgesEachHitWhenItsRecordIsComplete) {
  const std::string dir = TempDir("judge");
  const testing::BoardHammerTest test = testing::MakeBoardHammerTest(dir + "/live.csv", 2.0);
  HammerSession session(test.options);
  const Timing t = FeedAndWatch(session, test.records, 10000, 11);
  const HammerSnapshot before_end = session.Snapshot();
  EXPECT_EQ(before_end.hits.size(), 9u);
  EXPECT_EQ(before_end.pending_hits, 1u);  // hit 10: 1 s of its 2 s record
  EXPECT_FALSE(before_end.finished);
  std::printf(
      "hammer session: 3 channels at 5 kHz, 2 s records, %zu samples: each hit judged with "
      "FRF and modes updated in %.1f ms on average, %.1f ms at most (modes at most "
      "%.1f ms)\n",
      before_end.samples, t.mean_ms, t.worst_ms, t.worst_modes_ms);
  session.Finish();
  const HammerSnapshot s = session.Snapshot();
  ASSERT_EQ(s.hits.size(), 10u);
  EXPECT_TRUE(s.finished);
  for (std::size_t k = 0; k < 10; ++k)
    EXPECT_EQ(s.hits[k].verdict, kVerdicts[k]) << "hit " << k + 1 << ": " << s.hits[k].reason;
  EXPECT_GT(s.version, before_end.version);
  std::filesystem::remove_all(dir);
}

// The verdicts, the override, and the numbers of `frf-estimate --hits` / `modes --hits` on the
// saved files (EstimateFromRecording and IdentifyModes, what those commands run). Records of 6 s
// give lines enough (1/6 Hz) for the modal model's intervals.
TEST(HammerSession, VerdictsAndTheCliPathGiveTheSameNumbers) {
  const std::string dir = TempDir("cli-path");
  const testing::BoardHammerTest test = testing::MakeBoardHammerTest(dir + "/live.csv", 6.0);
  HammerSession session(test.options);
  const Timing timing = FeedAndWatch(session, test.records, 30000, 5);
  session.Finish();
  HammerSnapshot s = session.Snapshot();
  std::printf(
      "hammer session: 3 channels at 5 kHz, 6 s records, %zu samples: each hit judged "
      "with FRF and modes updated in %.1f ms on average, %.1f ms at most (modes at most "
      "%.1f ms)\n",
      s.samples, timing.mean_ms, timing.worst_ms, timing.worst_modes_ms);
  ASSERT_EQ(s.hits.size(), 10u);
  EXPECT_EQ(s.pending_hits, 0u);
  for (std::size_t k = 0; k < 10; ++k) {
    EXPECT_EQ(s.hits[k].verdict, kVerdicts[k]) << "hit " << k + 1 << ": " << s.hits[k].reason;
    EXPECT_EQ(s.hits[k].accepted, kVerdicts[k] == "ok") << "hit " << k + 1;
    EXPECT_FALSE(s.hits[k].by_operator);
    // The trigger: the first sample of the half-sine above 2 % of the largest force (the 500 N
    // overload): 10 N, reached 0.22 ms into a 100 N pulse of 4 ms and 0.7 ms into the 20 N tap
    // (asin(10 / 20) / pi x 4 ms), plus the sample the trigger waits for.
    EXPECT_NEAR(s.hits[k].t_s, test.hit_times_s[k], k == 6 ? 0.0009 : 0.0005) << "hit " << k + 1;
  }
  EXPECT_NE(s.hits[2].reason.find("double hit"), std::string::npos) << s.hits[2].reason;
  EXPECT_NE(s.hits[4].reason.find("force channel clipped"), std::string::npos) << s.hits[4].reason;
  EXPECT_NE(s.hits[6].reason.find("too weak"), std::string::npos) << s.hits[6].reason;
  EXPECT_NE(s.hits[9].reason.find("record ends before the hit's window"), std::string::npos);
  // The overload sits at the converter's top code: (4095 - 2048) / 4.096 N (sensors.json).
  EXPECT_NEAR(s.hits[4].peak_n, (4095 - 2048) / 4.096, 1.0);
  EXPECT_EQ(s.accepted, 6u);
  ASSERT_TRUE(s.modes.has_value()) << s.modes_error;
  ASSERT_EQ(s.modes->modes.size(), 2u);

  // The verdicts alone: what `frf-estimate --impact` does on the growing recording.
  EstimationOptions cli = test.options.estimation;
  cli.impact = true;
  const Estimated automatic = EstimateFromRecording(dir + "/live.csv", cli);
  ASSERT_EQ(automatic.hits.size(), 10u);
  for (std::size_t k = 0; k < 10; ++k) {
    EXPECT_EQ(automatic.hits[k].used, s.hits[k].accepted) << k;
    EXPECT_EQ(automatic.hits[k].t_s, s.hits[k].t_s);
    EXPECT_EQ(automatic.hits[k].peak_n, s.hits[k].peak_n);
    EXPECT_EQ(automatic.hits[k].note, s.hits[k].reason);
  }
  ExpectSameFrf(s.frf, automatic.frf);

  // The operator: hit 2 out, the light tap in.
  session.Reject(2);
  session.Accept(7);
  EXPECT_THROW(session.Accept(10), InputError);  // truncated: its record does not fit
  EXPECT_THROW(session.Reject(11), InputError);
  s = session.Snapshot();
  EXPECT_FALSE(s.hits[1].accepted);
  EXPECT_TRUE(s.hits[1].by_operator);
  EXPECT_TRUE(s.hits[6].accepted);
  EXPECT_EQ(s.accepted, 6u);
  EXPECT_EQ(s.frf.averages, 6u);
  ASSERT_TRUE(s.modes.has_value()) << s.modes_error;
  session.Save(dir);

  // The recording: the growing file, the saved one and the acquire writer's text are one text.
  device::LogPull pull;
  pull.layout = test.options.layout;
  pull.trailer.sample_period_us = test.options.sample_period_us;
  pull.trailer.decimation = test.options.decimation;
  pull.records = test.records;
  const std::string acquire = device::FormatLogCsv(pull, test.options.calibration, true);
  EXPECT_EQ(FileText(dir + "/recording.csv"), acquire);
  EXPECT_EQ(FileText(dir + "/live.csv"), acquire);
  // Their sidecars: the sampling instants the acquire writer states.
  device::WriteLogSidecar(dir + "/acquire.csv", pull, test.options.calibration, true,
                          test.options.instants);
  EXPECT_EQ(FileText(dir + "/recording.csv.json"), FileText(dir + "/acquire.csv.json"));
  EXPECT_EQ(FileText(dir + "/live.csv.json"), FileText(dir + "/acquire.csv.json"));

  // The hit list.
  const nlohmann::json hits = ReadJsonFile(dir + "/hits.json");
  ASSERT_EQ(hits.at("hits").size(), 10u);
  EXPECT_EQ(hits.at("hits")[1].at("decided_by"), "operator");
  EXPECT_EQ(hits.at("hits")[1].at("accepted"), false);
  EXPECT_EQ(hits.at("hits")[6].at("decided_by"), "operator");
  EXPECT_EQ(hits.at("hits")[6].at("verdict"), "too weak");
  EXPECT_EQ(hits.at("hits")[0].at("decided_by"), "auto");
  EXPECT_EQ(ReadAcceptedHits(dir + "/hits.json"), (std::vector<std::size_t>{1, 4, 6, 7, 8, 9}));

  // `frf-estimate --hits hits.json` and `modes --hits hits.json` on the saved recording: the same
  // bits.
  cli.hits_file = dir + "/hits.json";
  const Estimated chosen = EstimateFromRecording(dir + "/recording.csv", cli);
  ExpectSameFrf(s.frf, chosen.frf);
  EXPECT_FALSE(chosen.compensation.empty());  // the board's instants were stated and applied
  // With the ring-downs of the hits, as `vibid modes` on one recording checks them.
  const ident::ModeIdentification modes =
      IdentifyModes(chosen.frf, test.options.modes, &chosen.ringdowns);
  EXPECT_EQ(ModesToJson(modes.modes).dump(), ModesToJson(s.modes->modes).dump());
  EXPECT_EQ(DiagramToJson(modes.diagram).dump(), DiagramToJson(s.modes->diagram).dump());
  // The saved FRF files are the ones `frf-estimate -o` writes.
  EXPECT_EQ(FileText(dir + "/frf.csv"), ident::FormatFrfForPath(chosen.frf, "x.csv", 2));
  EXPECT_EQ(FileText(dir + "/frf.uff"), ident::FormatFrfForPath(chosen.frf, "x.uff", 2));
  // The modes against the rig's (examples/rig_nominal.json: 29.3691 and 68.0989 rad/s, as
  // `vibid modal` gives them), each inside its own 95 % interval widened to 1 %.
  const double truth[2] = {29.3691, 68.0989};
  for (std::size_t m = 0; m < 2; ++m) {
    const ident::ModeEstimate& e = s.modes->modes[m];
    EXPECT_NEAR(e.omega_rad_s, truth[m], 0.01 * truth[m]);
    EXPECT_TRUE(e.HasIntervals()) << "mode " << m + 1;
    EXPECT_LT(e.omega_ci95_rad_s[0], e.omega_rad_s);
    EXPECT_GT(e.omega_ci95_rad_s[1], e.omega_rad_s);
  }

  // Every warning the library gives, the modes' after the estimation's, as `vibid modes` prints
  // them; the band the modes were identified in.
  ASSERT_GE(s.warnings.size(), modes.warnings.size());
  EXPECT_TRUE(std::equal(modes.warnings.begin(), modes.warnings.end(),
                         s.warnings.end() - static_cast<std::ptrdiff_t>(modes.warnings.size())));
  EXPECT_EQ(s.band_min_hz, modes.diagram.freq_min_hz);
  EXPECT_EQ(s.band_max_hz, modes.diagram.freq_max_hz);
  EXPECT_GT(s.band_max_hz, 0.0);

  // The JSON the page draws.
  const nlohmann::json j = HammerSnapshotJson(s);
  EXPECT_EQ(j.at("hits").size(), 10u);
  EXPECT_EQ(j.at("frf").at("responses").size(), 2u);
  EXPECT_EQ(j.at("frf").at("freq_hz").size(), s.frf.lines());
  EXPECT_EQ(j.at("frf").at("responses")[1].at("magnitude")[5].get<double>(),
            std::abs(s.frf.h(5, 1)));
  EXPECT_EQ(j.at("modes").size(), 2u);
  EXPECT_TRUE(j.at("modes")[0].at("ci95").is_object());
  EXPECT_TRUE(j.at("diagram").is_object());
  const HitTraces t = session.Traces(3);
  EXPECT_EQ(t.force.size(), 30000);
  EXPECT_EQ(t.responses.cols(), 2);
  EXPECT_EQ(t.t_s[0], -468.0 / s.fs_hz);  // the automatic pretrigger: 30000 / 64 samples
  EXPECT_EQ(t.force_window[0], 1.0);
  EXPECT_EQ(t.force_window[29999], 0.0);
  EXPECT_EQ(HitTracesJson(t).at("force_window").size(), 30000u);
  std::filesystem::remove_all(dir);
}

// The CLI's default record (record_s 0: the shortest spacing between hits): each hit is judged
// when the next one's pulse is in (its record ends before that hit), the last one at the end; the
// end state is `frf-estimate --impact`'s on the recording with its defaults.
TEST(HammerSession, AutomaticRecordJudgesEachHitWhenTheNextComes) {
  const std::string dir = TempDir("auto-record");
  testing::BoardHammerTest test = testing::MakeBoardHammerTest(dir + "/live.csv", 6.0);
  test.options.estimation.impact_options.record_s = 0.0;
  HammerSession session(test.options);
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<std::size_t> size(1, 700);
  std::size_t judged = 0;
  const double fs_hz = 5000.0;
  for (std::size_t at = 0; at < test.records.size();) {
    const std::size_t n = std::min(size(rng), test.records.size() - at);
    session.Feed(std::span<const wire::LogRecord>(test.records.data() + at, n));
    at += n;
    const HammerSnapshot s = session.Snapshot();
    if (s.hits.size() == judged) continue;
    ASSERT_EQ(s.hits.size(), judged + 1);
    // Judged only once the next hit has been sampled (its pulse, then its rebound window of
    // 2 x 0.05 s), and in the first block after that.
    const double next_s = test.hit_times_s[judged + 1];
    EXPECT_GE(static_cast<double>(at) / fs_hz, next_s) << "hit " << judged + 1;
    EXPECT_LT(static_cast<double>(at - n) / fs_hz, next_s + 0.102) << "hit " << judged + 1;
    judged = s.hits.size();
  }
  EXPECT_EQ(judged, 9u);  // hit 10 waits for the end
  session.Finish();
  const HammerSnapshot s = session.Snapshot();
  EstimationOptions cli = test.options.estimation;
  cli.impact = true;
  const Estimated e = EstimateFromRecording(dir + "/live.csv", cli);
  ASSERT_EQ(s.hits.size(), e.hits.size());
  for (std::size_t k = 0; k < s.hits.size(); ++k) {
    EXPECT_EQ(e.hits[k].used, s.hits[k].accepted) << k;
    EXPECT_EQ(e.hits[k].note, s.hits[k].reason) << k;
  }
  ExpectSameFrf(s.frf, e.frf);
  // The record: the shortest spacing (record_s + 1 s at least), rounded down to a fast length.
  EXPECT_GE(s.frf.record_s, 6.0);
  EXPECT_LE(s.frf.record_s, 7.5);
  std::filesystem::remove_all(dir);
}

// The test kept whole in its folder as it goes: the hit list with every choice as it is made,
// and at any end (here the records stop mid-test, as Ctrl-C stops them) the whole test, which
// `frf-estimate --hits` reproduces.
TEST(HammerSession, KeepsTheTestWholeAsItGoes) {
  const std::string dir = TempDir("keep");
  testing::BoardHammerTest test = testing::MakeBoardHammerTest(dir + "/live.csv", 2.0);
  test.options.test_dir = dir;
  HammerSession session(test.options);
  std::size_t at = 0;
  while (session.Snapshot().hits.size() < 3) {
    const std::size_t n = std::min<std::size_t>(500, test.records.size() - at);
    ASSERT_GT(n, 0u);
    session.Feed(std::span<const wire::LogRecord>(test.records.data() + at, n));
    at += n;
  }
  nlohmann::json hits = ReadJsonFile(dir + "/hits.json");
  EXPECT_EQ(hits.at("hits").size(), 3u);
  session.Reject(1);
  hits = ReadJsonFile(dir + "/hits.json");  // journaled at once, while the test runs
  EXPECT_EQ(hits.at("hits")[0].at("accepted"), false);
  EXPECT_EQ(hits.at("hits")[0].at("decided_by"), "operator");
  EXPECT_FALSE(std::filesystem::exists(dir + "/recording.csv"));  // live.csv grows meanwhile
  session.Finish();
  for (const char* f : {"recording.csv", "hits.json", "frf.csv", "frf.uff"})
    EXPECT_TRUE(std::filesystem::exists(dir + "/" + f)) << f;
  EXPECT_EQ(FileText(dir + "/recording.csv"), FileText(dir + "/live.csv"));
  EstimationOptions cli = test.options.estimation;
  cli.impact = true;
  cli.hits_file = dir + "/hits.json";
  const Estimated chosen = EstimateFromRecording(dir + "/recording.csv", cli);
  EXPECT_EQ(FileText(dir + "/frf.csv"), ident::FormatFrfForPath(chosen.frf, "x.csv", 2));
  const std::size_t used = session.Snapshot().accepted;
  // A choice after the end rewrites the test.
  session.Accept(1);
  EXPECT_EQ(ReadJsonFile(dir + "/hits.json").at("hits")[0].at("accepted"), true);
  EXPECT_EQ(ReadAcceptedHits(dir + "/hits.json").size(), used + 1);
  // No hit accepted: no FRF beside a hit list that uses none.
  const HammerSnapshot s = session.Snapshot();
  for (const SessionHit& h : s.hits)
    if (h.accepted) session.Reject(h.index);
  EXPECT_TRUE(std::filesystem::exists(dir + "/hits.json"));
  EXPECT_FALSE(std::filesystem::exists(dir + "/frf.csv"));
  EXPECT_FALSE(std::filesystem::exists(dir + "/frf.uff"));
  std::filesystem::remove_all(dir);
}

TEST(HammerSession, RefusesOptionsItCannotHonour) {
  const std::string dir = TempDir("options");
  const testing::BoardHammerTest test = testing::MakeBoardHammerTest(dir + "/live.csv", 2.0);
  const auto refused = [&](HammerSessionOptions o, const std::string& words) {
    try {
      HammerSession s(o);
      ADD_FAILURE() << "accepted; expected a refusal naming " << words;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  HammerSessionOptions o = test.options;
  o.estimation.impact_options.record_s = -1.0;  // 0 is the automatic record; below it nothing
  refused(o, "--record-s");
  o = test.options;
  o.estimation.responses = "acc1_m_s2,acc3_m_s2";
  refused(o, "no column 'acc3_m_s2'");
  o = test.options;
  o.estimation.welch = true;
  refused(o, "--welch");
  o = test.options;
  o.estimation.use_hits = "1,2";
  refused(o, "--use-hits");
  o = test.options;
  o.modes.driving_point = "acc9_m_s2";
  refused(o, "--driving-point");
  o = test.options;
  o.estimation.impact_options.weak_hit_fraction = 1.5;
  refused(o, "weak-hit fraction");
  o = test.options;
  o.live_csv_path = dir + "/no-such-dir/live.csv";
  refused(o, "cannot create");
  // Records out of order or with a gap are refused, not recorded.
  HammerSession s(test.options);
  s.Feed(std::span<const wire::LogRecord>(test.records.data(), 10));
  EXPECT_THROW(s.Feed(std::span<const wire::LogRecord>(test.records.data() + 11, 10)), InputError);
  std::filesystem::remove_all(dir);
}

// Snapshots taken on another thread while records are fed: versions only grow, every copy is
// whole (hits and counts agree).
TEST(HammerSession, SnapshotsFromAnotherThread) {
  const std::string dir = TempDir("threads");
  const testing::BoardHammerTest test = testing::MakeBoardHammerTest(dir + "/live.csv", 2.0);
  HammerSession session(test.options);
  std::atomic<bool> done{false};
  std::uint64_t last = 0;
  bool ordered = true;
  bool consistent = true;
  std::thread reader([&] {
    while (!done.load()) {
      const HammerSnapshot s = session.Snapshot();
      ordered = ordered && s.version >= last;
      last = s.version;
      std::size_t accepted = 0;
      for (const SessionHit& h : s.hits) accepted += h.accepted ? 1 : 0;
      consistent = consistent && accepted == s.accepted && (accepted == 0) == (s.frf.lines() == 0);
    }
  });
  testing::FeedInBlocks(session, test.records, 3);
  session.Finish();
  done.store(true);
  reader.join();
  EXPECT_TRUE(ordered);
  EXPECT_TRUE(consistent);
  EXPECT_EQ(session.Snapshot().hits.size(), 10u);
  EXPECT_GT(session.Version(), last - 1);
  std::filesystem::remove_all(dir);
}

TEST(HitChoice, ListAndFile) {
  EXPECT_EQ(ParseHitList("1, 2,4"), (std::vector<std::size_t>{1, 2, 4}));
  EXPECT_THROW(ParseHitList("0,1"), InputError);
  EXPECT_THROW(ParseHitList("2,1"), InputError);
  EXPECT_THROW(ParseHitList("1,x"), InputError);
  const std::string dir = TempDir("hitlist");
  const auto write = [&](const std::string& text) {
    std::ofstream(dir + "/h.json") << text;
    return dir + "/h.json";
  };
  EXPECT_EQ(ReadAcceptedHits(write(R"({"format":"vibid-hammer-hits","hits":[
    {"index":1,"accepted":true},{"index":2,"accepted":false},{"index":3,"accepted":true}]})")),
            (std::vector<std::size_t>{1, 3}));
  EXPECT_THROW(ReadAcceptedHits(write(R"({"format":"vibid-hammer-hits","hits":[
    {"index":1,"acepted":true}]})")),
               InputError);  // a misspelt key is refused, never skipped
  EXPECT_THROW(ReadAcceptedHits(write(R"({"format":"vibid-hammer-hits","hits":[
    {"index":2,"accepted":true}]})")),
               InputError);  // hit 1 missing
  EXPECT_THROW(ReadAcceptedHits(write(R"({"hits":[{"index":1,"accepted":true}]})")), InputError);
  EXPECT_THROW(ReadAcceptedHits(write(R"({"format":"vibid-hammer-hits","hits":[
    {"index":1,"accepted":false}]})")),
               InputError);  // nothing to average
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace vibid::workflow
