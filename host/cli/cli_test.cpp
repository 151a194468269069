// Top-level CLI behaviour: usage errors, a misspelt command or option named with the nearest
// known one, help texts that state the real defaults, and defaults taken from where they are true.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>

#include <nlohmann/json.hpp>

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
  EXPECT_EQ(r.err,
            "vibid: error: unknown command 'frobnicate' for 'vibid'; 'vibid --help' lists the "
            "commands\n");
}

TEST(Cli, HelpAndVersionSucceed) {
  EXPECT_EQ(RunVibid({"--help"}).exit_code, 0);
  const auto v = RunVibid({"--version"});
  EXPECT_EQ(v.exit_code, 0);
  EXPECT_NE(v.out.find("vibid 0.1.0"), std::string::npos);
}

// A slip of the keyboard in a command or an option is named with what was meant, as the JSON
// readers name a misspelt key (exit 2, one line).
TEST(Cli, AMisspeltCommandOrOptionIsNamedWithTheNearestOne) {
  const struct {
    std::vector<std::string> args;
    std::string says;
  } cases[] = {
      {{"aquire", "--seconds", "1", "-o", "x.csv"},
       "unknown command 'aquire' for 'vibid' (did you mean 'acquire'?)"},
      {{"acquire", "--second", "1", "-o", "x.csv"},
       "unknown option '--second' for 'vibid acquire' (did you mean '--seconds'?)"},
      {{"acquire", "--seconds", "1", "--chanels", "force1", "-o", "x.csv"},
       "unknown option '--chanels' for 'vibid acquire' (did you mean '--channels'?)"},
      {{"dob", "desing", "examples/rig_nominal.json"},
       "unknown command 'desing' for 'vibid dob' (did you mean 'design'?)"},
      {{"modal", "examples/rig_nominal.json", "--jsno"},
       "unknown option '--jsno' for 'vibid modal' (did you mean '--json'?)"},
      {{"--devcie", "qemu", "info"},
       "unknown option '--devcie' for 'vibid' (did you mean '--device'?)"},
      {{"info", "--devcie", "qemu"},
       "unknown option '--devcie' for 'vibid info' (did you mean '--device'?)"},
      {{"acquire", "--frobnicate", "-o", "x.csv"},
       "unknown option '--frobnicate' for 'vibid acquire'; 'vibid acquire --help' lists its "
       "options"},
  };
  for (const auto& c : cases) {
    const CliResult r = RunVibid(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.says;
    EXPECT_EQ(r.err, "vibid: error: " + c.says + "\n");
  }
}

// Every word known but the line still wrong: vibid's words for what is wrong and the way out,
// never CLI11's own sentences.
TEST(Cli, ARefusedCommandLineIsSaidInVibidsWords) {
  const std::string model = VIBID_SOURCE_DIR "/examples/rig_nominal.json";
  const struct {
    std::vector<std::string> args;
    int exit_code;
    std::string says;
  } cases[] = {
      {{"--device", "usbip://127.0.0.1:1", "--device", "usbip://127.0.0.1:2", "info"},
       2,
       "--device was given 2 times; give it once; 'vibid info --help' shows its form"},
      {{"acquire", "-o", "x.csv"},
       2,
       "'vibid acquire' needs --seconds; 'vibid acquire --help' shows its form"},
      {{"modal", model, "other.json"},
       2,
       "'vibid modal' does not take other.json; 'vibid modal --help' shows its form"},
      {{"acquire", "--seconds", "1", "--decimation", "2", "--log-rate-hz", "1000"},
       2,
       "--log-rate-hz and --decimation cannot be given together; give one of them; 'vibid "
       "acquire --help' shows its form"},
      {{"acquire", "--seconds", "1", "--decimation", "two"},
       1,
       "--decimation two: must be in 1..1000"},
      {{"tfest", "a.csv", "--input", "f", "--output", "x", "--ic", "abc"},
       1,
       "--ic 'abc': expected one of zero,estimate"},
  };
  // CLI11's own phrasings, none of which may reach the user.
  const char* const cli11[] = {"required but received",
                               "is required",
                               "not expected",
                               " excludes ",
                               " requires ",
                               "Could not convert",
                               "not an allowed value",
                               "A subcommand",
                               "Expected exactly",
                               "Run with --help"};
  for (const auto& c : cases) {
    const CliResult r = RunVibid(c.args);
    EXPECT_EQ(r.exit_code, c.exit_code) << c.says << "\n" << r.err;
    EXPECT_EQ(r.err, "vibid: error: " + c.says + "\n");
    for (const char* words : cli11) EXPECT_EQ(r.err.find(words), std::string::npos) << r.err;
  }
  // A command that needs a command names those it has.
  const CliResult dob = RunVibid({"dob"});
  EXPECT_EQ(dob.exit_code, 2);
  EXPECT_EQ(dob.err.rfind("vibid: error: 'vibid dob' needs a command (design, ", 0), 0u) << dob.err;
  EXPECT_NE(dob.err.find("); 'vibid dob --help' says what each does\n"), std::string::npos)
      << dob.err;
}

// The help states each default the command runs with, and how the one chosen at run time is.
TEST(Cli, HelpStatesTheRealDefaults) {
  const CliResult acquire = RunVibid({"acquire", "--help"});
  ASSERT_EQ(acquire.exit_code, 0);
  EXPECT_NE(acquire.out.find("--rate-hz FLOAT:NUMBER>0=5000"), std::string::npos) << acquire.out;
  EXPECT_NE(acquire.out.find("logged by default while the board's observer runs"),
            std::string::npos)
      << acquire.out;
  const CliResult modes = RunVibid({"modes", "--help"});
  ASSERT_EQ(modes.exit_code, 0);
  EXPECT_EQ(modes.out.find("4:48:2"), std::string::npos) << "not a default runs use";
  EXPECT_NE(modes.out.find("highest order the"), std::string::npos) << modes.out;
  const CliResult design = RunVibid({"dob", "design", "--help"});
  ASSERT_EQ(design.exit_code, 0);
  EXPECT_NE(design.out.find("default: the load cell's in --sensors, else 100"), std::string::npos)
      << design.out;
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The observer's full scales come from the sensors file the board will scale with: the design
// `cal upload` then takes, where the 100 N default would be refused against the 500 N load cell.
TEST(Cli, DobDesignTakesTheFullScalesOfTheSensors) {
  const std::string dir = MakeTempDir("cli-design");
  const std::string model = VIBID_SOURCE_DIR "/examples/rig_nominal.json";
  const std::string sensors = VIBID_SOURCE_DIR "/examples/sensors.json";
  const CliResult from_sensors =
      RunVibid({"dob", "design", model, "--sensors", sensors, "-o", dir + "/s.json"});
  ASSERT_EQ(from_sensors.exit_code, 0) << from_sensors.err;
  EXPECT_EQ(from_sensors.err,
            "vibid: observer on mass 2 (force1's), force full scale 500 N from force1, sensor "
            "full scale 0.05 m from x2 (" +
                sensors + ")\n");
  const CliResult given = RunVibid({"dob", "design", model, "--force-fs-n", "500", "--sensor-fs",
                                    "0.05", "-o", dir + "/g.json"});
  ASSERT_EQ(given.exit_code, 0) << given.err;
  EXPECT_EQ(ReadText(dir + "/s.json"), ReadText(dir + "/g.json"))
      << "the sensors' full scales are those typed by hand";
  // A value that contradicts the sensors is refused, naming both.
  const CliResult clash =
      RunVibid({"dob", "design", model, "--sensors", sensors, "--force-fs-n", "100"});
  EXPECT_EQ(clash.exit_code, 1);
  EXPECT_EQ(clash.err,
            "vibid: error: --force-fs-n 100: the sensors give force1 (mass 2) a full scale of 500 "
            "N, and a channel has one range; leave --force-fs-n out to take the sensors', or "
            "correct the sensors file\n");
  // Without sensors the default is said to be one.
  const CliResult plain = RunVibid({"dob", "design", model, "-o", dir + "/d.json"});
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_NE(plain.err.find("force full scale 100 N, the default: give --sensors SENSORS.json"),
            std::string::npos)
      << plain.err;
  std::remove((dir + "/s.json").c_str());
  std::remove((dir + "/g.json").c_str());
  std::remove((dir + "/d.json").c_str());
  std::remove(dir.c_str());
}

}  // namespace
}  // namespace vibid::testing
