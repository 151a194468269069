// A recording's facts as the board states them (log_facts.hpp): each channel's rails through the
// board's own integer scaling against the closed form (code - offset) / counts_per_unit of
// examples/sensors.json, the sidecar's calibration CRC and emulator seed, and the CSV's value of a
// calibrated column written as the shortest decimal that keeps the board's number (0.0064 m for
// 640 encoder counts of 100 000 per metre, read back to the same Q31 word).
#include "vibid/device/log_facts.hpp"

#include <charconv>
#include <cmath>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "vibid/device/calibration_builder.hpp"
#include "vibid/device/log_table.hpp"
#include "vibid/shared/wire/log_record.hpp"

namespace vibid::device {
namespace {

// examples/sensors.json, as `vibid cal upload` puts it in the record.
wire::CalibrationRecord ExampleCalibration() {
  const SensorSet set = SensorsFromJson(nlohmann::json::parse(R"({
    "format": "vibid-sensors", "version": 1, "channels": {
    "force1": {"unit": "N", "counts_per_unit": 4.096, "offset_counts": 2048, "full_scale": 500, "dof": 2},
    "force2": {"unit": "N", "counts_per_unit": 40.96, "offset_counts": 2048, "full_scale": 50, "dof": 2},
    "acc1": {"unit": "m/s2", "counts_per_unit": 10.24, "offset_counts": 2048, "full_scale": 200, "dof": 1},
    "acc2": {"unit": "m/s2", "counts_per_unit": 10.24, "offset_counts": 2048, "full_scale": 200, "dof": 2},
    "x1": {"unit": "m", "counts_per_unit": 100000, "offset_counts": 0, "full_scale": 0.05, "dof": 1},
    "x2": {"unit": "m", "counts_per_unit": 100000, "offset_counts": 0, "full_scale": 0.05, "dof": 2}}})"),
                                        "sensors.json");
  wire::CalibrationRecord rec;
  rec.dof_count = 2;
  const char label[] = "rig A";
  std::copy(label, label + sizeof label - 1, rec.label.begin());
  for (std::size_t c = 0; c < wire::kChannelCount; ++c)
    rec.channels[c] = ToChannelScaling(*set[c], "c");
  return rec;
}

TEST(LogFacts, RailsAreTheConvertersEndsThroughTheBoardsScaling) {
  const wire::CalibrationRecord rec = ExampleCalibration();
  // Closed form (methods §11): value = (code - offset) / counts_per_unit, codes 0 and 4095. The
  // board's integer gain is finer than 1e-7 of it.
  const auto [f_lo, f_hi] = ChannelRails(wire::Channel::kForce1, rec.channels[0], 12);
  EXPECT_NEAR(f_lo, -2048.0 / 4.096, 1e-7 * 500.0);
  EXPECT_NEAR(f_hi, 2047.0 / 4.096, 1e-7 * 500.0);
  const auto [a_lo, a_hi] = ChannelRails(wire::Channel::kAccel1, rec.channels[2], 12);
  EXPECT_NEAR(a_lo, -2048.0 / 10.24, 1e-7 * 200.0);
  EXPECT_NEAR(a_hi, 2047.0 / 10.24, 1e-7 * 200.0);
  // An encoder's counter never reaches its ends; the scaling saturates first, at the full scale
  // 0.05 m (the Q31 word's ends: -2^31 and 2^31 - 1 of 2^31, as their shortest decimals).
  const auto [x_lo, x_hi] = ChannelRails(wire::Channel::kEncoder1, rec.channels[4], 12);
  const double fs = static_cast<double>(rec.channels[4].full_scale);
  EXPECT_EQ(std::nearbyint(x_lo / fs * 2147483648.0), -2147483648.0);
  EXPECT_EQ(std::nearbyint(x_hi / fs * 2147483648.0), 2147483647.0);
  EXPECT_NEAR(x_lo, -0.05, 1e-9);
  // Uncalibrated: the codes themselves.
  const auto [c_lo, c_hi] = ChannelRails(wire::Channel::kAccel2, wire::DefaultScaling(), 12);
  EXPECT_EQ(c_lo, 0.0);
  EXPECT_EQ(c_hi, 4095.0);
}

TEST(LogFacts, TheSidecarStatesTheBoardTheCalibrationAndEachChannel) {
  const wire::CalibrationRecord rec = ExampleCalibration();
  LogPull p;
  p.layout = wire::LogLayout{0b010101, 0};  // force1, acc1, x1
  p.trailer.sample_period_us = 200;
  p.trailer.decimation = 1;
  BoardContext board;
  board.info = wire::InfoResponse{};
  board.info->board_id = wire::BoardId::kEmulator;
  board.info->fw_major = 2;
  board.info->fw_minor = 1;
  board.info->adc_bits = 12;
  board.serial = "EMU0000000000000007";
  board.clips = wire::ClipResponse{};
  board.clips->clipped[0] = 3;
  ident::AcquisitionFacts asked;
  asked.seconds = 2.0;
  asked.scenario = "hammer";
  const ident::RecordingFacts f =
      LogFacts(p, 10000, rec, true, board, asked, "2026-12-07T04:30:00.125Z");
  EXPECT_EQ(f.columns, (std::vector<std::string>{"t_s", "force1_n", "acc1_m_s2", "x1_m"}));
  EXPECT_EQ(*f.fs, 5000.0);
  ASSERT_TRUE(f.board && f.calibration && f.acquisition);
  EXPECT_EQ(f.board->board, "emulator");
  EXPECT_EQ(f.board->firmware, "2.1.0");
  EXPECT_EQ(*f.acquisition->emulator_seed, 7u);
  EXPECT_EQ(f.acquisition->scenario, "hammer");
  EXPECT_EQ(f.acquisition->records, 10000u);
  EXPECT_EQ(f.calibration->label, "rig A");
  std::array<std::uint8_t, wire::kCalRecordBytes> bytes{};
  wire::EncodeCalibrationRecord(rec, bytes);
  EXPECT_EQ(f.calibration->crc32, wire::StoredRecordCrc(bytes));
  const ident::ChannelFacts* force = f.Channel("force1_n");
  ASSERT_NE(force, nullptr);
  EXPECT_EQ(force->unit_str, "N");
  EXPECT_NEAR(*force->counts_per_unit, 4.096, 1e-6);
  EXPECT_EQ(*force->clipped_samples, 3u);
  EXPECT_EQ(force->code_range->second, 4095.0);
  EXPECT_EQ(f.Channel("x1_m")->unit_str, "m");
  EXPECT_EQ(EmulatorSeedOfSerial("EMU00000000000000G7"), std::nullopt);
  EXPECT_EQ(EmulatorSeedOfSerial("0123"), std::nullopt);
}

TEST(LogFacts, ACalibratedValueIsWrittenAsTheShortestDecimalThatKeepsTheBoardsNumber) {
  const wire::CalibrationRecord rec = ExampleCalibration();
  LogPull p;
  p.layout = wire::LogLayout{0b010001, 0};  // force1, x1
  p.trailer.sample_period_us = 200;
  p.trailer.decimation = 1;
  const std::int32_t counts[] = {640, -1, 4999, 123457};
  for (std::uint32_t k = 0; k < 4; ++k) {
    wire::LogRecord r;
    r.sample_index = k;
    r.raw[0] = 3000 << wire::kLogAdcFractionBits;
    r.raw[4] = counts[k];
    p.records.push_back(r);
  }
  const LogTable t = MakeLogTable(p, rec, true);
  EXPECT_EQ(t.columns[2](0), 0.0064);  // in memory as in the file
  const std::string rows = FormatLogCsvRows(p, rec, true);
  std::istringstream in(rows);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line.substr(line.rfind(',') + 1), "0.0064") << line;
  // Every cell reads back to the board's word: nearbyint(value / full scale x 2^31), as the
  // observer's replay takes it.
  const double fs = static_cast<double>(rec.channels[4].full_scale);
  in.clear();
  in.str(rows);
  for (Eigen::Index i = 0; std::getline(in, line); ++i) {
    const std::string cell = line.substr(line.rfind(',') + 1);
    double v = 0.0;
    std::from_chars(cell.data(), cell.data() + cell.size(), v);
    std::uint32_t clips = 0;
    const double q = wire::ScaleChannel(counts[i], rec.channels[4], clips);
    EXPECT_EQ(std::nearbyint(v / fs * 2147483648.0), q) << cell;
    EXPECT_EQ(v, t.columns[2](i)) << cell;
  }
}

}  // namespace
}  // namespace vibid::device
