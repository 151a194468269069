// The sampling instants end to end: the board states them in get-info, a common tone on two
// converter inputs shows them as a phase, and the host's FRF takes that phase off.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <complex>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <thread>

#include <nlohmann/json.hpp>

#include "run_cli.hpp"
#include "state_wait.hpp"
#include "target.hpp"
#include "vibid/device/log_table.hpp"
#include "vibid/ident/sample_instants.hpp"
#include "vibid/ident/spectral.hpp"
#include "vibid/shared/board_profile.hpp"

namespace vibid::hil {
namespace {

constexpr double kPi = std::numbers::pi;

class SamplingInstantsTest : public ::testing::Test {
 protected:
  void SetUp() override { target = MakeTarget(); }
  std::unique_ptr<Target> target;
};

TEST_F(SamplingInstantsTest, InfoStatesTheBoardProfilesInstants) {
  auto c = target->Connect();
  EXPECT_EQ(c->info().protocol_minor, wire::kProtocolMinor);
  const std::optional<wire::SamplingInfoResponse> s = c->GetSamplingInfo();
  ASSERT_TRUE(s.has_value());
  for (std::size_t k = 0; k < wire::kChannelCount; ++k)
    EXPECT_EQ(s->sample_instant_ns[k], kBoardProfile.sample_instant_ns(k)) << "channel " << k;
  // force1 and acc1 at one instant, force2 one conversion (68 ADC clocks, 3238 ns) later.
  EXPECT_EQ(s->sample_instant_ns[0], s->sample_instant_ns[2]);
  EXPECT_EQ(s->sample_instant_ns[1] - s->sample_instant_ns[0], 3238u);
}

TEST_F(SamplingInstantsTest, ACommonToneShowsTheInstantsAndTheHostTakesThemOff) {
  auto c = target->Connect();
  if ((c->info().capabilities & wire::kCapScenarioSelect) == 0)
    GTEST_SKIP() << "needs a simulated rig (select-scenario)";
  // A 2437 Hz tone at 0.9 of full scale on the converter inputs; force2 and acc1 at 10 kHz for
  // 1 s: 2437 whole cycles on the 1 Hz lines of one 10000-sample segment.
  const double fs = 10000.0, f = 2437.0;
  const std::uint32_t n = 10000;
  c->SelectScenario("tone", std::vector<float>{static_cast<float>(f), 0.9f});
  wire::AcqConfigureRequest cfg;
  cfg.sample_period_us = 100;
  cfg.channel_mask = (1u << 1) | (1u << 2);  // force2, acc1
  cfg.decimation = 1;
  cfg.record_limit = n;
  c->Configure(cfg);
  c->StartAcquisition();
  const auto deadline = std::chrono::steady_clock::now() + hil::kStateWait;
  while (c->GetStatus().acq_state != wire::AcqState::kDone) {
    ASSERT_LT(std::chrono::steady_clock::now(), deadline)
        << "waited " << hil::kStateWait.count() << " s for " << n << " records";
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  const device::LogPull pull = c->PullLog();
  ASSERT_EQ(pull.records.size(), n);

  // The recording's sidecar as `vibid acquire` writes it, read back by the host.
  const std::optional<wire::SamplingInfoResponse> instants = c->GetSamplingInfo();
  const device::LogTable table = device::MakeLogTable(pull, wire::CalibrationRecord{}, false);
  ASSERT_TRUE(instants.has_value());
  const std::optional<ident::SampleInstants> header = ident::ParseRecordingSidecar(
      ident::FormatRecordingSidecar(table.names, device::SampleInstantsUs(table, pull, *instants)),
      table.names, "tone.csv.json");
  ASSERT_TRUE(header.has_value());
  ASSERT_EQ(table.names[1], "force2_counts");
  ASSERT_EQ(table.names[2], "acc1_counts");

  // H1 of acc1 to force2 with one rectangular segment: the tone's line is exactly
  // exp(j omega (t_acc1 - t_force2)): acc1 converts 68 ADC clocks of 21 MHz before force2.
  ident::WelchOptions o;
  o.segment_samples = n;
  o.overlap_samples = 0;
  o.window = ident::Window::kRectangular;
  o.detrend = ident::Detrend::kConstant;
  const std::vector<const Eigen::VectorXd*> responses{&table.columns[2]};
  ident::Frf frf = ident::FrfFromSpectra(ident::WelchSpectra(table.columns[1], responses, fs, o),
                                         ident::Estimator::kH1, ident::Quantity::kAcceleration);
  const auto line = static_cast<Eigen::Index>(f);
  ASSERT_DOUBLE_EQ(frf.freq_hz(line), f);
  const double expected = -2.0 * kPi * f * 68.0 / 21e6;  // -0.049583 rad (-2.841 deg)
  const double measured = std::arg(frf.h(line, 0));
  // Quantization and the converters' noise (about 0.5 code rms on a 1843-code amplitude) over
  // 10000 samples: about 5e-6 rad rms; 3e-5 rad is 1.9 ns of instant.
  EXPECT_NEAR(measured, expected, 3e-5);
  ident::CompensateSampleInstants(frf, *header->Of("force2_counts"), {*header->Of("acc1_counts")});
  const double compensated = std::arg(frf.h(line, 0));
  EXPECT_NEAR(compensated, 0.0, 3e-5);
  std::printf(
      "%s: tone %.0f Hz, acc1 / force2 phase %.6f rad (expected %.6f), %.2e rad after "
      "compensation\n",
      target->Name().c_str(), f, measured, expected, compensated);
}

// What a user sees: `vibid info --json` and the sidecar of a recording from `vibid acquire`.
TEST(SamplingInstantsCli, InfoAndTheRecordingStateTheInstants) {
  if (MakeTarget()->Name() != "emu") GTEST_SKIP() << "needs the emu target (a vibid-emu process)";
  EmulatorProcess emu(EmulatorBinary());
  const auto info = vibid::testing::RunVibid({"--device", emu.device_spec(), "info", "--json"});
  ASSERT_EQ(info.exit_code, 0) << info.err;
  const nlohmann::json instants = nlohmann::json::parse(info.out).at("sample_instants_us");
  // 56 / 21 MHz = 2.667 us (whole ns) for force1, the accelerometers and the encoders; force2
  // one 68-clock conversion later, 124 / 21 MHz = 5.905 us.
  EXPECT_EQ(instants.at("force1").get<double>(), 2.667);
  EXPECT_EQ(instants.at("force2").get<double>(), 5.905);
  EXPECT_EQ(instants.at("acc1").get<double>(), 2.667);
  EXPECT_EQ(instants.at("acc2").get<double>(), 2.667);
  EXPECT_EQ(instants.at("x1").get<double>(), 2.667);
  EXPECT_EQ(instants.at("x2").get<double>(), 2.667);

  const std::string dir = vibid::testing::MakeTempDir("instants-cli");
  const std::string rec = dir + "/rec.csv";
  const auto a = vibid::testing::RunVibid({"--device", emu.device_spec(), "acquire", "--seconds",
                                           "0.1", "--channels", "force1,force2,x2", "-o", rec});
  ASSERT_EQ(a.exit_code, 0) << a.err;
  std::ifstream in(rec);
  std::string first;
  std::getline(in, first);
  EXPECT_EQ(first, "t_s,force1_counts,force2_counts,x2_counts") << "the header row first";
  const nlohmann::json sidecar =
      nlohmann::json::parse(vibid::testing::ReadFileBytes(rec + ".json"));
  EXPECT_EQ(sidecar.at("columns"),
            nlohmann::json({"t_s", "force1_counts", "force2_counts", "x2_counts"}));
  // Version 2 of the sidecar states each channel's instant beside its other facts.
  nlohmann::json instants_by_column = nlohmann::json::object();
  for (const nlohmann::json& channel : sidecar.at("channels"))
    instants_by_column[channel.at("name").get<std::string>()] = channel.at("sample_instant_us");
  EXPECT_EQ(
      instants_by_column,
      nlohmann::json({{"force1_counts", 2.667}, {"force2_counts", 5.905}, {"x2_counts", 2.667}}));
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
}

}  // namespace
}  // namespace vibid::hil
