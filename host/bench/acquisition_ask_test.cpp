#include "vibid/bench/acquisition_ask.hpp"

#include <gtest/gtest.h>

#include "vibid/common/error.hpp"

namespace vibid::bench {
namespace {

nlohmann::json Ask() {
  return {{"sample_period_us", 200}, {"channels", {"force1", "acc2"}}, {"seconds", 2.5}};
}

std::string Refusal(const nlohmann::json& j) {
  try {
    ParseAcquisitionAsk(j);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(AcquisitionAsk, ReadsTheRequestIntoTheBoardsConfiguration) {
  nlohmann::json j = Ask();
  j["log_dob"] = true;
  j["fit_measured"] = "force1";
  const AcquisitionAsk a = ParseAcquisitionAsk(j);
  const wire::AcqConfigureRequest cfg = ConfigFor(a);
  EXPECT_EQ(cfg.sample_period_us, 200u);
  EXPECT_EQ(cfg.channel_mask, (1u << 0) | (1u << 3));  // force1 = channel 0, acc2 = channel 3
  EXPECT_EQ(cfg.record_limit, 12500u);                 // 2.5 s x 5000 Hz
  EXPECT_EQ(cfg.decimation, 1u);
  EXPECT_EQ(cfg.flags, wire::kAcqFlagStream | wire::kAcqFlagLogDob);
  EXPECT_EQ(a.fit_lowpass_hz, 0.0);  // the raw d̂ unless asked
  j["fit_lowpass_hz"] = 4;
  EXPECT_EQ(ParseAcquisitionAsk(j).fit_lowpass_hz, 4.0);
}

TEST(AcquisitionAsk, RefusesUnknownKeysTypesAndRanges) {
  nlohmann::json unknown = Ask();
  unknown["second"] = 1;
  EXPECT_NE(Refusal(unknown).find("unknown key 'second'"), std::string::npos);
  nlohmann::json fraction = Ask();
  fraction["sample_period_us"] = 200.5;
  EXPECT_NE(Refusal(fraction).find("whole number"), std::string::npos);
  nlohmann::json fast = Ask();
  fast["sample_period_us"] = 99;  // below wire::kMinSamplePeriodUs = 100
  EXPECT_NE(Refusal(fast).find("outside 100..1000000"), std::string::npos);
  nlohmann::json negative = Ask();
  negative["seconds"] = -1;
  EXPECT_NE(Refusal(negative).find("'seconds'"), std::string::npos);
  nlohmann::json text = Ask();
  text["seconds"] = "2";
  EXPECT_NE(Refusal(text).find("'seconds' must be a number"), std::string::npos);
  nlohmann::json channel = Ask();
  channel["channels"] = {"force3"};
  EXPECT_NE(Refusal(channel).find("unknown channel 'force3'"), std::string::npos);
  nlohmann::json twice = Ask();
  twice["channels"] = {"acc1", "acc1"};
  EXPECT_NE(Refusal(twice).find("twice"), std::string::npos);
  nlohmann::json fit = Ask();
  fit["fit_measured"] = "acc2";
  EXPECT_NE(Refusal(fit).find("not a load cell"), std::string::npos);
  nlohmann::json lowpass = Ask();
  lowpass["log_dob"] = true;
  lowpass["fit_measured"] = "force1";
  lowpass["fit_lowpass_hz"] = 2500;  // half of 5000 Hz: no low-pass there
  EXPECT_NE(Refusal(lowpass).find("'fit_lowpass_hz' must lie in [0, 2500"), std::string::npos);
  lowpass["fit_lowpass_hz"] = -1;
  EXPECT_NE(Refusal(lowpass).find("'fit_lowpass_hz' must lie in"), std::string::npos);
  lowpass.erase("fit_measured");
  lowpass["fit_lowpass_hz"] = 4;
  EXPECT_NE(Refusal(lowpass).find("needs 'fit_measured'"), std::string::npos);
  EXPECT_NE(Refusal(nlohmann::json::array()).find("JSON object"), std::string::npos);
  nlohmann::json missing = Ask();
  missing.erase("channels");
  EXPECT_NE(Refusal(missing).find("'channels' is missing"), std::string::npos);
}

}  // namespace
}  // namespace vibid::bench
