// The hammer session's saved files through the `vibid` binary: `frf-estimate --hits` writes the
// FRF files the session saved, byte for byte, and `modes --hits --json` prints the session's modes
// and stabilization diagram; `--use-hits` with the same numbers gives the same.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "run_cli.hpp"
#include "testing/board_hammer_test.hpp"
#include "vibid/workflow/hammer_session.hpp"
#include "vibid/workflow/result_json.hpp"

namespace vibid::workflow {
namespace {

using vibid::testing::ReadFileBytes;
using vibid::testing::RunVibid;

TEST(HammerSessionCli, FrfEstimateAndModesOnTheSavedFilesShowTheSessionsNumbers) {
  const std::string dir = vibid::testing::MakeTempDir("hammer-cli");
  const workflow::testing::BoardHammerTest test =
      workflow::testing::MakeBoardHammerTest(dir + "/live.csv", 6.0);
  HammerSession session(test.options);
  workflow::testing::FeedInBlocks(session, test.records, 9);
  session.Finish();
  session.Reject(2);
  session.Accept(7);
  session.Save(dir);
  const HammerSnapshot s = session.Snapshot();
  ASSERT_TRUE(s.modes.has_value()) << s.modes_error;

  const std::vector<std::string> estimation = {dir + "/recording.csv",
                                               "--force",
                                               "force1_n",
                                               "--response",
                                               "acc1_m_s2,acc2_m_s2",
                                               "--impact",
                                               "--record-s",
                                               "6",
                                               "--trigger",
                                               "0.02",
                                               "--exp-window",
                                               "0.01"};
  const auto with = [&](std::vector<std::string> more) {
    std::vector<std::string> args = {"frf-estimate"};
    args.insert(args.end(), estimation.begin(), estimation.end());
    args.insert(args.end(), more.begin(), more.end());
    return args;
  };
  auto r = RunVibid(with({"--hits", dir + "/hits.json", "-o", dir + "/cli.csv"}));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("6 average(s)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("hit 7 at"), std::string::npos) << r.out;
  EXPECT_EQ(ReadFileBytes(dir + "/cli.csv"), ReadFileBytes(dir + "/frf.csv"));
  r = RunVibid(with({"--hits", dir + "/hits.json", "-o", dir + "/cli.uff"}));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(ReadFileBytes(dir + "/cli.uff"), ReadFileBytes(dir + "/frf.uff"));
  r = RunVibid(with({"--use-hits", "1,4,6,7,8,9", "-o", dir + "/listed.csv"}));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(ReadFileBytes(dir + "/listed.csv"), ReadFileBytes(dir + "/frf.csv"));
  // The verdicts alone (no --hits) average hit 2 and leave the light tap out: another FRF.
  r = RunVibid(with({"-o", dir + "/auto.csv"}));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(ReadFileBytes(dir + "/auto.csv"), ReadFileBytes(dir + "/frf.csv"));
  // A truncated hit cannot be chosen.
  r = RunVibid(with({"--use-hits", "1,10", "-o", dir + "/bad.csv"}));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("hit 10"), std::string::npos) << r.err;

  std::vector<std::string> modes = {"modes"};
  modes.insert(modes.end(), estimation.begin(), estimation.end());
  for (const std::string& a : {std::string("--hits"), dir + "/hits.json", std::string("--json"),
                               std::string("--driving-point"), std::string("acc2_m_s2")})
    modes.push_back(a);
  r = RunVibid(modes);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("modes").dump(), ModesToJson(s.modes->modes).at("modes").dump());
  EXPECT_EQ(j.at("stabilization").dump(), DiagramToJson(s.modes->diagram).dump());
  EXPECT_EQ(j.at("modes").size(), 2u);
  EXPECT_TRUE(j.at("modes")[0].at("ci95").at("omega_rad_s").is_array());
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace vibid::workflow
