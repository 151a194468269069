// The model test built from a calibration day: the observer the record carries replayed on the
// recording's columns (routed as the record routes them) gives the same design as the library
// on the board's own integers, the record with the test decodes, and every recording that
// cannot give it is refused naming the cause.
#include "vibid/device/watch_day.hpp"

#include <gtest/gtest.h>

#include <random>

#include "test_filter.hpp"
#include "vibid/common/error.hpp"
#include "vibid/device/calibration_builder.hpp"
#include "vibid/dob/quantize.hpp"
#include "vibid/model/model.hpp"

namespace vibid::device {
namespace {

constexpr double kFsHz = 1000.0;

wire::CalibrationRecord RecordWithObserver() {
  RecordInputs in;
  Eigen::VectorXd m(2), k(2), c(2);
  m << 2.0, 1.5;
  k << 4000.0, 3000.0;
  c << 5.0, 3.0;
  in.model = model::MakeChain(m, k, c);
  in.label = "rig";
  // The test filter: a force (100 N) and an acceleration (490 m/s^2) on mass 2.
  in.observer = wire::testing::TestFilter(static_cast<std::uint32_t>(kFsHz));
  in.sensors[0] = SensorScaling{.unit = wire::Unit::kNewton,
                                .counts_per_unit = 4.096,
                                .offset_counts = 2048,
                                .full_scale = 100.0,
                                .dof = 1};
  in.sensors[1] = SensorScaling{.unit = wire::Unit::kNewton,
                                .counts_per_unit = 40.96,
                                .offset_counts = 2048,
                                .full_scale = 50.0,
                                .dof = 1};
  in.sensors[3] = SensorScaling{.unit = wire::Unit::kMeterPerSecond2,
                                .counts_per_unit = 4.096,
                                .offset_counts = 2048,
                                .full_scale = 490.0,
                                .dof = 1};
  return BuildCalibrationRecord(in);
}

// `seconds` of the day as the log writes it: each column a Q31 integer times its full scale
// over 2^31 (exact in double), Gaussian noise a tenth of the full scale.
Recording Day(double seconds, double fs_hz = kFsHz) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 0.1);
  const auto n = static_cast<Eigen::Index>(seconds * fs_hz);
  CsvTable t;
  t.source = "day.csv";
  t.names = {"t_s", "force1_n", "force2_n", "acc2_m_s2"};
  t.columns.assign(4, Eigen::VectorXd(n));
  const double fs[] = {100.0, 50.0, 490.0};
  for (Eigen::Index i = 0; i < n; ++i) {
    t.columns[0](i) = static_cast<double>(i) / fs_hz;
    for (int c = 0; c < 3; ++c) {
      const double q = std::round(noise(rng) * 2147483648.0);
      t.columns[static_cast<std::size_t>(c + 1)](i) = q * fs[c] / 2147483648.0;
    }
  }
  return MakeRecording(t, {});
}

std::string Refusal(wire::CalibrationRecord r, const Recording& day, WatchDayOptions o = {}) {
  try {
    AttachWatchTest(r, day, o, "day.csv");
  } catch (const InputError& e) {
    return e.what();
  }
  return "accepted";
}

TEST(WatchDay, TheDesignIsTheLibrarysOnTheBoardsOwnIntegers) {
  const Recording day = Day(120.0);
  wire::CalibrationRecord r = RecordWithObserver();
  WatchDayOptions o;
  o.reference = "force2";
  const dob::WatchDesign got = AttachWatchTest(r, day, o, "day.csv");

  // The reference: the observer's inputs in its order (force1, acc2) through the board's
  // replay, force2 as Q31 against d_hat's 200 N full scale.
  fixed::FilterDescription d;
  ASSERT_EQ(fixed::DecodeDescription(r.dob, d), Status::kOk);
  const dob::FixedRun run =
      dob::RunFixed(d, {day.table.Column("force1_n"), day.table.Column("acc2_m_s2")});
  std::vector<std::int32_t> f2;
  for (const double v : day.table.Column("force2_n"))
    f2.push_back(static_cast<std::int32_t>(std::lround(v / 50.0 * 2147483648.0)));
  const dob::WatchDesign want = dob::DesignWatch(run.d_hat_q31, f2, 50.0 / 200.0, kFsHz, {});
  EXPECT_EQ(got.params.window_samples, want.params.window_samples);
  EXPECT_EQ(got.params.residual_gain, want.params.residual_gain);
  EXPECT_EQ(got.params.reference_gain, want.params.reference_gain);
  EXPECT_NE(got.params.reference_gain, 0);
  EXPECT_EQ(got.params.center, want.params.center);
  EXPECT_EQ(got.params.h, want.params.h);
  EXPECT_DOUBLE_EQ(got.arl0_windows, want.arl0_windows);
  EXPECT_EQ(r.watch_reference_channel, 1);
  EXPECT_NE(r.flags & wire::kCalFlagHasWatch, 0);
  EXPECT_EQ(r.watch.h, want.params.h);
  std::array<std::uint8_t, wire::kCalRecordBytes> bytes{};
  wire::EncodeCalibrationRecord(r, bytes);
  wire::CalibrationRecord back;
  EXPECT_EQ(wire::DecodeCalibrationRecord(bytes, back), Status::kOk);
  EXPECT_EQ(back.watch.window_samples, want.params.window_samples);
  EXPECT_NE(WatchDesignText(got).find("model test: windows of"), std::string::npos);
}

TEST(WatchDay, TheBoardsDhatMustBeThisObserversReplay) {
  Recording day = Day(120.0);
  wire::CalibrationRecord r = RecordWithObserver();
  fixed::FilterDescription d;
  ASSERT_EQ(fixed::DecodeDescription(r.dob, d), Status::kOk);
  const dob::FixedRun run =
      dob::RunFixed(d, {day.table.Column("force1_n"), day.table.Column("acc2_m_s2")});
  Eigen::VectorXd q(static_cast<Eigen::Index>(run.d_hat_q31.size()));
  for (std::size_t i = 0; i < run.d_hat_q31.size(); ++i)
    q(static_cast<Eigen::Index>(i)) = run.d_hat_q31[i];
  day.table.names.push_back("d_hat_q31");
  day.table.columns.push_back(q);
  EXPECT_EQ(Refusal(r, day), "accepted");
  day.table.columns.back()(4321) += 1.0;
  EXPECT_NE(Refusal(r, day).find("differs from this observer's replay from sample 4321"),
            std::string::npos)
      << Refusal(r, day);
}

TEST(WatchDay, RefusesWhatCannotGiveTheTest) {
  const Recording day = Day(120.0);
  wire::CalibrationRecord none = RecordWithObserver();
  none.flags = 0;
  EXPECT_NE(Refusal(none, day).find("this calibration has no observer"), std::string::npos);
  EXPECT_NE(Refusal(RecordWithObserver(), Day(120.0, 500.0))
                .find("sampled at 500 Hz, but the observer steps at 1000 Hz"),
            std::string::npos);
  Recording no_acc = day;
  no_acc.table.names[3] = "acc1_m_s2";
  EXPECT_NE(Refusal(RecordWithObserver(), no_acc).find("has no column 'acc2_m_s2'"),
            std::string::npos)
      << Refusal(RecordWithObserver(), no_acc);
  WatchDayOptions o;
  o.reference = "acc1";
  EXPECT_NE(Refusal(RecordWithObserver(), day, o).find("is not a load cell"), std::string::npos);
  // Too short for 50 windows: the library's refusal, with its way out.
  EXPECT_NE(Refusal(RecordWithObserver(), Day(2.0)).find("50"), std::string::npos)
      << Refusal(RecordWithObserver(), Day(2.0));
}

}  // namespace
}  // namespace vibid::device
