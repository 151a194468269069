// One range per channel: the calibration record takes each channel's full scale from the sensors
// and refuses an observer designed for another, naming both values and the ways out, instead of
// overwriting the sensor's range (a 500 N cell cut to 100 N clips every hit above 100 N).
#include "vibid/device/calibration_builder.hpp"

#include <gtest/gtest.h>

#include "test_filter.hpp"
#include "vibid/common/error.hpp"
#include "vibid/device/acquire_plan.hpp"
#include "vibid/device/calibration_upload.hpp"
#include "vibid/device/error.hpp"
#include "vibid/model/model.hpp"
#include "vibid/shared/wire/byte_order.hpp"
#include "vibid/shared/wire/crc32.hpp"

namespace vibid::device {
namespace {

// A 2-mass chain (the values do not matter here; the record carries them).
RecordInputs Inputs(double force_fs_n, double accel_fs_m_s2) {
  RecordInputs in;
  Eigen::VectorXd m(2), k(2), c(2);
  m << 2.0, 1.5;
  k << 4000.0, 3000.0;
  c << 5.0, 3.0;
  in.model = model::MakeChain(m, k, c);
  in.label = "rig";
  // The test filter's inputs: a force and an acceleration on mass 2 (0-based dof 1), designed
  // for 100 N and 490 m/s^2 (test_filter.hpp).
  in.observer = wire::testing::TestFilter();
  in.sensors[0] = SensorScaling{.unit = wire::Unit::kNewton,
                                .counts_per_unit = 4.096,
                                .offset_counts = 2048,
                                .full_scale = force_fs_n,
                                .dof = 1};
  in.sensors[3] = SensorScaling{.unit = wire::Unit::kMeterPerSecond2,
                                .counts_per_unit = 4.096,
                                .offset_counts = 2048,
                                .full_scale = accel_fs_m_s2,
                                .dof = 1};
  return in;
}

std::string MessageOf(const RecordInputs& in) {
  try {
    BuildCalibrationRecord(in);
  } catch (const InputError& e) {
    return e.what();
  }
  return "accepted";
}

TEST(CalibrationBuilder, MatchingRangesKeepTheSensorsFullScale) {
  const wire::CalibrationRecord r = BuildCalibrationRecord(Inputs(100.0, 490.0));
  EXPECT_EQ(r.channels[0].full_scale, 100.0f);
  EXPECT_EQ(r.channels[3].full_scale, 490.0f);
  EXPECT_EQ(r.dob_input_channel[0], 0);  // force -> force1
  EXPECT_EQ(r.dob_input_channel[1], 3);  // acceleration on mass 2 -> acc2
}

TEST(CalibrationBuilder, AConflictingRangeIsRefusedNotOverwritten) {
  // examples/sensors.json's 500 N cell against an observer made with the default 100 N.
  EXPECT_EQ(MessageOf(Inputs(500.0, 490.0)),
            "force1: the sensors give a full scale of 500 N, the observer's input 1 was designed "
            "for 100 N; a channel has one range: design the observer for the sensor's (vibid dob "
            "design --force-fs-n 500), or, if the sensor's range is 100 N, set "
            "channels.force1.full_scale to it in the sensors file");
  EXPECT_EQ(MessageOf(Inputs(100.0, 200.0)),
            "acc2: the sensors give a full scale of 200 m/s2, the observer's input 2 was designed "
            "for 490 m/s2; a channel has one range: design the observer for the sensor's (vibid "
            "dob design --sensor-fs 200), or, if the sensor's range is 490 m/s2, set "
            "channels.acc2.full_scale to it in the sensors file");
}

// A chain of n masses from ground (springs k1..kn, k1 to ground), sensors: acc1 on mass 1, x1 on
// 2, acc2 on 3, x2 on 4 (as far as the chain goes), the load cell on the last mass.
RecordInputs Chain(int n) {
  RecordInputs in;
  Eigen::VectorXd m(n), k(n), c(n);
  for (int i = 0; i < n; ++i) {
    m[i] = 1.4 - 0.2 * i;
    k[i] = 4200.0 - 600.0 * i;
    c[i] = 3.0 - 0.5 * i;
  }
  in.model = model::MakeChain(m, k, c);
  in.label = "chain";
  const int on[] = {2, 4, 3, 5};  // wire::Channel of acc1, x1, acc2, x2
  for (int i = 0; i < n && i < 4; ++i) {
    in.sensors[static_cast<std::size_t>(on[i])] =
        SensorScaling{.unit = on[i] >= 4 ? wire::Unit::kMeter : wire::Unit::kMeterPerSecond2,
                      .counts_per_unit = on[i] >= 4 ? 100000.0 : 10.24,
                      .offset_counts = on[i] >= 4 ? 0 : 2048,
                      .full_scale = on[i] >= 4 ? 0.05 : 200.0,
                      .dof = i};
  }
  in.sensors[0] = SensorScaling{.unit = wire::Unit::kNewton,
                                .counts_per_unit = 4.096,
                                .offset_counts = 2048,
                                .full_scale = 500.0,
                                .dof = n - 1};
  return in;
}

// The record holds chains of up to four masses: the n x n blocks of M, C, K at row stride
// kMaxDof, as the model states them (for n = 4: k34 = -k4 = -2400 N/m, k44 = k4, c22 = c2 + c3).
TEST(CalibrationBuilder, FourMassChainFillsTheWholeBlocks) {
  const wire::CalibrationRecord r = BuildCalibrationRecord(Chain(4));
  constexpr std::size_t w = wire::kMaxDof;
  EXPECT_EQ(r.dof_count, 4);
  EXPECT_EQ(r.mass_kg[3 * w + 3], static_cast<float>(1.4 - 0.6));
  EXPECT_EQ(r.stiffness_n_per_m[2 * w + 3], -2400.0f);
  EXPECT_EQ(r.stiffness_n_per_m[3 * w + 2], -2400.0f);
  EXPECT_EQ(r.stiffness_n_per_m[3 * w + 3], 2400.0f);
  EXPECT_EQ(r.damping_ns_per_m[1 * w + 1], static_cast<float>(2.5 + 2.0));
  EXPECT_EQ(r.stiffness_n_per_m[0 * w + 2], 0.0f);
  EXPECT_EQ(r.channels[5].dof, 3);  // x2 on mass 4
  EXPECT_EQ(r.channels[0].dof, 3);  // the load cell on mass 4
  // Three masses leave row and column 4 zero.
  const wire::CalibrationRecord r3 = BuildCalibrationRecord(Chain(3));
  EXPECT_EQ(r3.dof_count, 3);
  for (std::size_t i = 0; i < w; ++i) {
    EXPECT_EQ(r3.stiffness_n_per_m[3 * w + i], 0.0f);
    EXPECT_EQ(r3.mass_kg[i * w + 3], 0.0f);
  }
}

TEST(CalibrationBuilder, FiveMassesAreRefusedWithTheBoardsLimit) {
  RecordInputs in = Chain(4);
  Eigen::VectorXd m(5), k(5), c(5);
  m.setConstant(1.0);
  k.setConstant(1000.0);
  c.setConstant(1.0);
  in.model = model::MakeChain(m, k, c);
  EXPECT_EQ(MessageOf(in), "the board holds models of 1 to 4 masses; this model has 5");
  in = Chain(3);
  in.sensors[5] = in.sensors[4];  // x2 on mass 4 of a 3-mass chain
  in.sensors[5]->dof = 3;
  EXPECT_EQ(MessageOf(in), "x2 sits on mass 4 but the model has 3");
}

// The bench's identify measures each mass as the record places its sensors: the accelerometer on
// a mass first, else its encoder.
TEST(BoardRecord, ResponseColumnsFollowTheSensorsMasses) {
  const wire::CalibrationRecord r4 = BuildCalibrationRecord(Chain(4));
  EXPECT_EQ(ResponseColumnsOnMasses(r4, 4),
            (std::vector<std::string>{"acc1_m_s2", "x1_m", "acc2_m_s2", "x2_m"}));
  // The hammer's load cell on mass 4: the driving point is x2; on no mass: none.
  EXPECT_EQ(DrivingPointColumn(r4, ResponseColumnsOnMasses(r4, 4)), "x2_m");
  wire::CalibrationRecord off = r4;
  off.channels[0].dof = wire::kNoDof;
  EXPECT_EQ(DrivingPointColumn(off, ResponseColumnsOnMasses(r4, 4)), "");
  // Both an accelerometer and an encoder on mass 2: the accelerometer.
  RecordInputs in = Chain(3);
  in.sensors[3]->dof = 1;  // acc2 on mass 2 beside x1
  in.sensors[5] = in.sensors[4];
  in.sensors[5]->dof = 2;  // x2 on mass 3
  EXPECT_EQ(ResponseColumnsOnMasses(BuildCalibrationRecord(in), 3),
            (std::vector<std::string>{"acc1_m_s2", "acc2_m_s2", "x2_m"}));
  in = Chain(3);
  in.sensors[3].reset();  // nothing on mass 3
  try {
    static_cast<void>(ResponseColumnsOnMasses(BuildCalibrationRecord(in), 3));
    FAIL() << "a mass without a sensor accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("mass 3 of 3 has no calibrated accelerometer or encoder"),
              std::string::npos)
        << e.what();
  }
}

// The observer where the record puts the hammer's load cell: mass 4 of Chain(4), fed by x2 at its
// full scale (float32 of 0.05 m); with only an accelerometer there, that one; with the load cell
// on no mass, none.
TEST(BoardRecord, ObserverSitsOnTheLoadCellsMass) {
  const std::optional<ObserverPlacement> p4 = ObserverPlacementOf(BuildCalibrationRecord(Chain(4)));
  ASSERT_TRUE(p4.has_value());
  EXPECT_EQ(p4->dof, 4);
  EXPECT_EQ(p4->sensor, "disp");
  EXPECT_EQ(p4->sensor_fs, static_cast<double>(0.05f));
  const std::optional<ObserverPlacement> p3 = ObserverPlacementOf(BuildCalibrationRecord(Chain(3)));
  ASSERT_TRUE(p3.has_value());  // Chain(3): acc2 on mass 3, no encoder there
  EXPECT_EQ(p3->dof, 3);
  EXPECT_EQ(p3->sensor, "acc");
  EXPECT_EQ(p3->sensor_fs, 200.0);
  wire::CalibrationRecord off = BuildCalibrationRecord(Chain(4));
  off.channels[0].dof = wire::kNoDof;
  EXPECT_FALSE(ObserverPlacementOf(off).has_value());
}

// A board of an older release sends a version-2 record (876 bytes, two masses at most): named,
// with the way out, not "does not decode".
TEST(BoardRecord, AnOlderVersionNamesTheWayOut) {
  std::vector<std::uint8_t> v2(876, 0);
  wire::StoreU32(v2, wire::kCalOffMagic, wire::kCalMagic);
  wire::StoreU16(v2, wire::kCalOffVersion, 2);
  wire::StoreU16(v2, wire::kCalOffLength, 876);
  wire::StoreU32(v2, 872, wire::ComputeCrc32(std::span<const std::uint8_t>(v2).first(872)));
  try {
    DecodeBoardRecord(v2);
    FAIL() << "a version-2 record accepted";
  } catch (const DeviceError& e) {
    EXPECT_EQ(std::string(e.what()),
              "the board's calibration record is version 2 (876 bytes); this host reads version "
              "3 (1020 bytes, chains of up to 4 masses): flash the firmware of this host's "
              "release (vibid flash), then upload and commit the calibration again (vibid cal "
              "upload, vibid cal commit)");
  }
  // The current version decodes.
  std::array<std::uint8_t, wire::kCalRecordBytes> bytes{};
  wire::EncodeCalibrationRecord(BuildCalibrationRecord(Chain(4)), bytes);
  EXPECT_EQ(DecodeBoardRecord(bytes).dof_count, 4);
}

}  // namespace
}  // namespace vibid::device
