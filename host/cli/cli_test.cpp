// Top-level CLI behaviour: usage errors, help, version.
#include <gtest/gtest.h>

#include "run_cli.hpp"

namespace vibid::testing {
namespace {

TEST(Cli, NoSubcommandIsAUsageError) {
  const auto r = RunVibid({});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_FALSE(r.err.empty());
}

TEST(Cli, UnknownSubcommandIsAUsageError) {
  const auto r = RunVibid({"frobnicate"});
  EXPECT_EQ(r.exit_code, 2);
}

TEST(Cli, HelpAndVersionSucceed) {
  EXPECT_EQ(RunVibid({"--help"}).exit_code, 0);
  const auto v = RunVibid({"--version"});
  EXPECT_EQ(v.exit_code, 0);
  EXPECT_NE(v.out.find("vibid 0.1.0"), std::string::npos);
}

}  // namespace
}  // namespace vibid::testing
