#include "vibid/bench/acquisition_ask.hpp"

#include <gtest/gtest.h>

#include "vibid/common/error.hpp"
#include "vibid/device/link_budget.hpp"

namespace vibid::bench {
namespace {

// The emulated board's profile: a 96 KiB log and 1000 reports/s over the link.
wire::InfoResponse Board() {
  wire::InfoResponse info;
  info.log_capacity_bytes = 96 * 1024;
  info.link_reports_per_s = 1000;
  return info;
}

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
  const wire::AcqConfigureRequest cfg = ConfigFor(a, Board());
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

// The page's opening form: 5 kHz, four channels and d̂, 60 s. A record is 4 x 2 bytes of channels
// and 4 of d̂ = 12 bytes, 4 in a report's 56-byte payload: the link carries 4000 records/s. At
// every sample the 96 KiB log (6144 records of 16 bytes with their tick) fills at 1000 records/s,
// after 6.144 s: "auto" takes the next decimation the board has, 2 (2500 records/s, carried
// whole), for 60 s, and every sample for 5.5 s, which the log holds.
TEST(AcquisitionAsk, AutoLogRateTakesTheHighestThatTheLogHolds) {
  nlohmann::json j = {{"sample_period_us", 200},
                      {"channels", {"force1", "force2", "acc1", "acc2"}},
                      {"seconds", 60},
                      {"log_dob", true},
                      {"log_rate_hz", "auto"}};
  wire::AcqConfigureRequest cfg = ConfigFor(ParseAcquisitionAsk(j), Board());
  EXPECT_EQ(cfg.decimation, 2u);
  EXPECT_EQ(cfg.record_limit, 150000u);  // 60 s x 2500 records/s
  const device::LinkBudget b = device::ComputeLinkBudget(Board(), cfg);
  EXPECT_TRUE(b.KeepsUp());
  j["seconds"] = 5.5;
  cfg = ConfigFor(ParseAcquisitionAsk(j), Board());
  EXPECT_EQ(cfg.decimation, 1u);
  EXPECT_EQ(cfg.record_limit, 27500u);
  EXPECT_NEAR(device::ComputeLinkBudget(Board(), cfg).overflow_after_s, 6.144, 1e-12);
  // Every sample for 60 s is refused in the page's words: its controls, no --allow-drops.
  j["seconds"] = 60;
  j.erase("log_rate_hz");
  cfg = ConfigFor(ParseAcquisitionAsk(j), Board());
  EXPECT_EQ(cfg.decimation, 1u);
  const std::string refusal = device::DescribeOverflow(device::ComputeLinkBudget(Board(), cfg), 60,
                                                       device::AdviceWords::kBenchPage);
  EXPECT_NE(refusal.find("overflows after 6.1 s of the 60.0 s"), std::string::npos) << refusal;
  EXPECT_NE(refusal.find("choose a log rate of 2500 Hz or lower (auto takes the highest that "
                         "fits), fewer channels, or 6.1 seconds or less"),
            std::string::npos)
      << refusal;
  EXPECT_EQ(refusal.find("--"), std::string::npos) << refusal;
  // A log rate asked for: 1000 Hz is every 5th sample.
  j["log_rate_hz"] = 1000;
  cfg = ConfigFor(ParseAcquisitionAsk(j), Board());
  EXPECT_EQ(cfg.decimation, 5u);
  EXPECT_EQ(cfg.record_limit, 60000u);
  j["log_rate_hz"] = 1500;  // 5000 / 1500 is no whole decimation
  EXPECT_NE(Refusal(j).find("'log_rate_hz' 1500"), std::string::npos) << Refusal(j);
  j["log_rate_hz"] = 5000.0 / 3;  // 3 is not 2^a 5^b
  EXPECT_NE(Refusal(j).find("2^a 5^b"), std::string::npos);
  j["log_rate_hz"] = "fast";
  EXPECT_NE(Refusal(j).find("\"auto\""), std::string::npos);
  j["log_rate_hz"] = 0;
  EXPECT_NE(Refusal(j).find("must be > 0"), std::string::npos);
}

// The budget box: what the log holds, for how long, and whether the acquisition fits.
TEST(AcquisitionAsk, BudgetLinesSayWhatTheLogHoldsAndForHowLong) {
  wire::AcqConfigureRequest cfg;
  cfg.sample_period_us = 200;
  cfg.channel_mask = 0x0f;
  cfg.flags = wire::kAcqFlagStream | wire::kAcqFlagLogDob;
  cfg.decimation = 1;
  const auto lines = device::DescribeBudget(device::ComputeLinkBudget(Board(), cfg), 60);
  ASSERT_EQ(lines.size(), 6u);
  EXPECT_EQ(lines[0].second, "12 bytes, 4 per 64-byte report");
  EXPECT_EQ(lines[1].second, "5000 records/s (every sample of 5000 Hz)");
  EXPECT_EQ(lines[2].second, "4000 records/s (1000 reports/s)");
  EXPECT_EQ(lines[3].second, "6144 records (96 KiB): 1.23 s at the log rate");
  EXPECT_EQ(lines[4].second, "after 6.1 s (it gains 1000 records/s)");
  EXPECT_EQ(lines[5].second, "60.0 s: does not fit (records would be dropped)");
  cfg.decimation = 2;
  const auto fits = device::DescribeBudget(device::ComputeLinkBudget(Board(), cfg), 60);
  EXPECT_EQ(fits[1].second, "2500 records/s (every 2nd sample of 5000 Hz)");
  EXPECT_EQ(fits[4].second, "never: the link keeps up");
  EXPECT_EQ(fits[5].second, "60.0 s: fits, nothing dropped");
}

}  // namespace
}  // namespace vibid::bench
