// The FRF route refuses a record that is no hammer test (a step, a controller's pulse, a held
// random command: the ECP cart driven by its motor's voltage) and names the time-domain methods;
// the system-identification commands state the residual tests they fail; greybox's stds hold
// against repeated runs.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "vibid/common/error.hpp"
#include "vibid/common/testing/real_data.hpp"
#include "vibid/workflow/estimate.hpp"
#include "vibid/workflow/sysid_run.hpp"

namespace vibid::workflow {
namespace {

std::string Refusal(const std::string& path, bool impact) {
  EstimationOptions o;
  o.force = "V_volt";
  o.responses = "X_encoder_counts*1.7857e-5";
  o.sensor = "disp";
  o.impact = impact;
  try {
    EstimateFromRecording(path, o);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// data/ecp_cart_motor_driven/: steps, pulses and a held random voltage, every one refused by
// default and with --impact (which took a 0 V sample for a hit), naming the methods that take it.
TEST(NotHammer, MotorVoltageRecordsAreRefusedWithTheTimeDomainMethods) {
  VIBID_SHARED_DATA_OR_SKIP(dir, "ecp_cart_motor_driven");
  for (const char* file :
       {"steps_kmed_nomass_data0000.csv", "pulse_kmed_2mass_data0000.csv",
        "steps_klow_2mass_compression_data0000.csv", "rand_kmed_nomass_data0000.csv"}) {
    for (bool impact : {false, true}) {
      const std::string why = Refusal(dir + "/" + file, impact);
      EXPECT_NE(why.find("not a hammer test"), std::string::npos) << file << ": " << why;
      EXPECT_NE(why.find("vibid tfest"), std::string::npos) << why;
      EXPECT_NE(why.find("vibid decay"), std::string::npos) << why;
    }
  }
}

// The same cart's pulse record through tfest and greybox: the linear fits are right (the
// documented figures), and their own residual tests fail (dry friction): the text says so.
TEST(NotHammer, FailedResidualTestsAreStated) {
  VIBID_SHARED_DATA_OR_SKIP(dir, "ecp_cart_motor_driven");
  SysidRecord rec{dir + "/pulse_kmed_2mass_data0000.csv",
                  "I_amp*-178.57",
                  "X_encoder_counts*1.7857e-3",
                  std::nullopt,
                  "none",
                  1};
  TfestRequest t;
  t.record = rec;
  const SysidReport tf = RunTfest(t);
  ASSERT_TRUE(tf.json.contains("residuals"));
  EXPECT_FALSE(tf.json["residuals"]["whiteness"]["passed"].get<bool>());
  ASSERT_FALSE(tf.cautions.empty());
  EXPECT_NE(tf.text.find("CAUTION: the residuals are not white"), std::string::npos) << tf.text;
  EXPECT_EQ(tf.json["cautions"].size(), tf.cautions.size());

  GreyboxRequest g;
  g.record = rec;
  g.fix = "M=1.3";
  const SysidReport gb = RunGreybox(g);
  EXPECT_NE(gb.text.find("CAUTION: the residuals are not white"), std::string::npos) << gb.text;
  EXPECT_NE(gb.json["std_basis"].get<std::string>().find("Newey-West"), std::string::npos);

  PemRequest p;
  p.poly.record = rec;
  p.structure = "oe";
  p.orders = "2,2,1";
  const SysidReport pem = RunPem(p);
  EXPECT_NE(pem.text.find("CAUTION: the residuals"), std::string::npos) << pem.text;
}

// Repeated pulse runs of one configuration (the first two pieces of kmed's recordings with 2
// masses and without): greybox's interval on each run (1.96 std) must not be narrower than the
// runs' spread (their standard deviation), and the stds of white residuals were 4 to 7 times too
// small for it. (The no-mass recording's third piece, 1 400 samples, gives M 7 % lower, outside
// these intervals: not covered, docs/sysid.md says so; the 2-mass third piece is 400 samples of a
// constant voltage.)
TEST(NotHammer, GreyboxIntervalsAreNotNarrowerThanRepeatedRuns) {
  VIBID_SHARED_DATA_OR_SKIP(dir, "ecp_cart_motor_driven");
  const std::vector<std::vector<std::string>> sets = {
      {"pulse_kmed_2mass_data0000.csv", "pulse_kmed_2mass_data0001.csv"},
      {"pulse_kmed_nomass_data0000.csv", "pulse_kmed_nomass_data0001.csv"}};
  for (const auto& runs : sets) {
    std::vector<double> m, sd, sd_white;
    for (const std::string& run : runs) {
      GreyboxRequest g;
      g.record = {dir + "/" + run, "I_amp*-178.57", "X_encoder_counts*1.7857e-5",
                  std::nullopt,    "none",          1};
      const SysidReport r = RunGreybox(g);
      m.push_back(r.json["parameters"]["M"]["value"].get<double>());
      sd.push_back(r.json["parameters"]["M"]["std"].get<double>());
      sd_white.push_back(r.json["parameters"]["M"]["std_white"].get<double>());
    }
    const auto n = static_cast<double>(m.size());
    double mean = 0.0;
    for (double v : m) mean += v / n;
    double spread = 0.0;
    for (double v : m) spread += (v - mean) * (v - mean) / (n - 1.0);
    spread = std::sqrt(spread);
    for (std::size_t i = 0; i < m.size(); ++i) {
      std::printf("%s: M %.4f +- %.4f (white %.4f), runs' sd %.4f\n", runs[i].c_str(), m[i], sd[i],
                  sd_white[i], spread);
      EXPECT_GE(1.96 * sd[i], spread) << runs[i];
      EXPECT_GE(sd[i], 3.0 * sd_white[i]) << runs[i];
    }
  }
}

}  // namespace
}  // namespace vibid::workflow
