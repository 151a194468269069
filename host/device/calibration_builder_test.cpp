// One range per channel: the calibration record takes each channel's full scale from the sensors
// and refuses an observer designed for another, naming both values and the ways out, instead of
// overwriting the sensor's range (a 500 N cell cut to 100 N clips every hit above 100 N).
#include "vibid/device/calibration_builder.hpp"

#include <gtest/gtest.h>

#include "test_filter.hpp"
#include "vibid/common/error.hpp"
#include "vibid/model/model.hpp"

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

}  // namespace
}  // namespace vibid::device
