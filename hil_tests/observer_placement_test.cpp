// `vibid dob design --sensors` puts the observer where `cal upload` with the same sensors accepts
// it, on chains of 3 and 4 masses as on 2: on the mass load cell 1 sits on, fed by that mass's
// encoder (else its accelerometer), with no --input-dof, --output-dof or --sensor given. The
// upload, commit and start on the emulated chain are the proof.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

#include "emulator_process.hpp"
#include "run_cli.hpp"
#include "target.hpp"

namespace vibid::hil {
namespace {

void WriteText(const std::string& path, const std::string& text) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  ASSERT_NE(f, nullptr) << path;
  std::fputs(text.c_str(), f);
  std::fclose(f);
}

struct Chain {
  int masses;
  const char* sensor;  // the observer's sensor on the last mass: x1 (encoder) or acc2
  const char* sensor_unit;
  const char* said;
};

class ObserverPlacementTest : public ::testing::TestWithParam<Chain> {};

TEST_P(ObserverPlacementTest, TheDesignGoesWhereTheUploadTakesIt) {
  const Chain c = GetParam();
  if (MakeTarget()->emulator() == nullptr || EmulatorBinary().empty())
    GTEST_SKIP() << "needs the emulator's rig files (the emu target)";
  const std::string n = std::to_string(c.masses);
  const std::string rig = VIBID_SOURCE_DIR "/host/emulator/rigs/chain" + n + ".json";
  const std::string model = VIBID_SOURCE_DIR "/examples/chain" + n + "_nominal.json";
  EmulatorProcess emu(EmulatorBinary(), {"--rig", rig, "--seed", "2"});
  const std::string dir = testing::MakeTempDir("placement" + n);
  // The hammer's load cell and the observer's sensor on the last mass (dof counted from 1),
  // the accelerometer acc1 on mass 1.
  const std::string sensors = dir + "/sensors.json";
  const std::string sensor_channel =
      std::string(c.sensor_unit) == "m"
          ? R"("unit": "m", "counts_per_unit": 100000, "offset_counts": 0, "full_scale": 0.05)"
          : R"("unit": "m/s2", "counts_per_unit": 10.24, "offset_counts": 2048, "full_scale": 200)";
  WriteText(sensors, R"({"format": "vibid-sensors", "version": 1, "channels": {
    "force1": {"unit": "N", "counts_per_unit": 4.096, "offset_counts": 2048, "full_scale": 500, "dof": )" +
                         n + R"(},
    "acc1": {"unit": "m/s2", "counts_per_unit": 10.24, "offset_counts": 2048, "full_scale": 200, "dof": 1},
    ")" + std::string(c.sensor) +
                         R"(": {)" + sensor_channel + R"(, "dof": )" + n + "}}}\n");

  const std::string design = dir + "/design.json";
  const testing::CliResult designed = testing::RunVibid(
      {"dob", "design", model, "--fs-hz", "1000", "--sensors", sensors, "-o", design});
  ASSERT_EQ(designed.exit_code, 0) << designed.err;
  EXPECT_NE(designed.err.find("observer on mass " + n + " (force1's)"), std::string::npos)
      << designed.err;
  EXPECT_NE(designed.err.find(c.said), std::string::npos) << designed.err;

  const std::vector<std::string> device = {"--device", emu.device_spec()};
  const auto vibid = [&](std::vector<std::string> args) {
    args.insert(args.begin(), device.begin(), device.end());
    return testing::RunVibid(args);
  };
  const testing::CliResult up =
      vibid({"cal", "upload", model, "--design", design, "--sensors", sensors});
  ASSERT_EQ(up.exit_code, 0) << up.err;
  ASSERT_EQ(vibid({"cal", "commit"}).exit_code, 0);
  const testing::CliResult started = vibid({"dob", "start"});
  EXPECT_EQ(started.exit_code, 0) << started.err;
  // The record's observer reads the last mass's sensor.
  const testing::CliResult shown = vibid({"cal", "show", "--json"});
  ASSERT_EQ(shown.exit_code, 0) << shown.err;
  const nlohmann::json record = nlohmann::json::parse(shown.out);
  EXPECT_EQ(record["channels"]["force1"]["dof"], c.masses) << shown.out;
  EXPECT_FALSE(record["observer"].is_null()) << shown.out;
}

INSTANTIATE_TEST_SUITE_P(Chains, ObserverPlacementTest,
                         ::testing::Values(Chain{3, "x1", "m", "sensor full scale 0.05 m from x1"},
                                           Chain{4, "acc2", "m/s2",
                                                 "sensor full scale 200 m/s2 from acc2"}),
                         [](const ::testing::TestParamInfo<Chain>& i) {
                           return "Masses" + std::to_string(i.param.masses);
                         });

}  // namespace
}  // namespace vibid::hil
