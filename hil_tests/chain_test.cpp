// A chain of three masses through the whole acquisition path: vibid-emu with the shipped
// host/emulator/rigs/chain3.json (masses 1 and 2 on the accelerometers, mass 3 on encoder x1, the
// hammer on mass 3 as the rig file says), one hammer test of accelerations and an encoder
// displacement recorded by `vibid acquire`, `vibid modes` on it: the chain's three modes at the
// rig truth's frequencies. The board is left uncalibrated here, so the host scales the converter
// counts (file-formats.md); Workflow.ThreeMassChainRunsTheObserverSteps calibrates it for the
// chain.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "emulator_process.hpp"
#include "run_cli.hpp"
#include "target.hpp"

namespace vibid::hil {
namespace {

const std::string kRig = std::string(VIBID_SOURCE_DIR) + "/host/emulator/rigs/chain3.json";

nlohmann::json Json(const testing::CliResult& r) {
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return nlohmann::json::parse(r.out);
}

TEST(Chain, ThreeMassesOnAccelerometersAndAnEncoderGiveTheTruthsModes) {
  if (MakeTarget()->emulator() == nullptr || EmulatorBinary().empty())
    GTEST_SKIP() << "needs the emulator's rig files (the emu target)";
  EmulatorProcess emu(EmulatorBinary(), {"--rig", kRig, "--seed", "3"});
  const std::string dir = testing::MakeTempDir("chain3");

  // The truth's modes: `vibid modal` of the rig's true model, as `vibid-emu --print-truth`
  // states it (the model library's modes are checked against the closed form of a uniform chain
  // in emulator_rig_test's Rig.ThreeAndFourMassChainsRingAtTheClosedFormModes).
  const testing::CliResult truth =
      testing::RunProgram(EmulatorBinary(), {"--rig", kRig, "--print-truth"});
  ASSERT_EQ(truth.exit_code, 0) << truth.err;
  {
    std::FILE* f = std::fopen((dir + "/truth.json").c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fputs(truth.out.c_str(), f);
    std::fclose(f);
  }
  const nlohmann::json modal = Json(testing::RunVibid({"modal", dir + "/truth.json", "--json"}));
  ASSERT_EQ(modal["modes"].size(), 3u) << modal.dump();

  // One hammer test: the load cell, both accelerometers and encoder x1 (10-byte records, 5 per
  // report: 5000 records/s, the link carries 5 kHz). The hammer's mass and the hits' spacing
  // are the rig's (parameters 0).
  const std::string rec = dir + "/modal.csv";
  const testing::CliResult acquired =
      testing::RunVibid({"--device", emu.device_spec(), "acquire", "--seconds", "100", "--rate-hz",
                         "5000", "--channels", "force1,acc1,acc2,x1", "--no-dob", "--scenario",
                         "hammer", "--scenario-param", "0", "150", "0", "0", "-o", rec});
  ASSERT_EQ(acquired.exit_code, 0) << acquired.err;
  EXPECT_EQ(acquired.err.find("dropped"), std::string::npos) << acquired.err;

  // Uncalibrated: the converter counts, scaled here as the rig's sensors are (±500 N and
  // ±200 m/s² on 12 bits, 10 µm encoder counts); each response as what it measures.
  const nlohmann::json modes =
      Json(testing::RunVibid({"modes", rec, "--force", "force1_counts*0.244140625", "--response",
                              "acc1_counts*0.09765625,acc2_counts*0.09765625,x1_counts*1e-5",
                              "--sensor", "acc,acc,disp", "--exp-window", "0.1", "--json"}));
  ASSERT_EQ(modes["modes"].size(), 3u) << modes.dump(1);
  for (std::size_t r = 0; r < 3; ++r) {
    const double f_truth = modal["modes"][r]["freq_hz"].get<double>();
    const double f = modes["modes"][r]["freq_hz"].get<double>();
    std::printf("mode %zu: %.4f Hz (truth %.4f Hz, %+.3f %%)\n", r + 1, f, f_truth,
                100.0 * (f - f_truth) / f_truth);
    EXPECT_NEAR(f, f_truth, 0.01 * f_truth) << "mode " << r + 1;
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace vibid::hil
