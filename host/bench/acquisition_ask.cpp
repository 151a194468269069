#include "vibid/bench/acquisition_ask.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "vibid/common/error.hpp"
#include "vibid/common/json_keys.hpp"
#include "vibid/device/link_budget.hpp"
#include "vibid/device/log_table.hpp"
#include "vibid/shared/fixed/decimator.hpp"

namespace vibid::bench {
namespace {

constexpr double kMaxSeconds = 24.0 * 3600.0;

std::string Text(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

double Number(const nlohmann::json& v, const std::string& key) {
  Require(v.is_number(), "'" + key + "' must be a number");
  const double x = v.get<double>();
  Require(std::isfinite(x), "'" + key + "' must be finite");
  return x;
}

}  // namespace

AcquisitionAsk ParseAcquisitionAsk(const nlohmann::json& body) {
  Require(body.is_object(), "the request must be a JSON object");
  RequireKnownKeys(body,
                   {"sample_period_us", "channels", "seconds", "log_rate_hz", "log_dob", "scenario",
                    "scenario_params", "fit_measured", "fit_lowpass_hz"},
                   "the acquisition request");
  AcquisitionAsk a;
  Require(body.contains("sample_period_us"), "'sample_period_us' is missing");
  Require(body.contains("seconds"), "'seconds' is missing");
  Require(body.contains("channels"), "'channels' is missing");
  const nlohmann::json& p = body["sample_period_us"];
  Require(p.is_number_integer(), "'sample_period_us' must be a whole number of microseconds");
  const auto period = p.get<std::int64_t>();
  Require(period >= wire::kMinSamplePeriodUs && period <= wire::kMaxSamplePeriodUs,
          "'sample_period_us' " + std::to_string(period) + " is outside " +
              std::to_string(wire::kMinSamplePeriodUs) + ".." +
              std::to_string(wire::kMaxSamplePeriodUs) + " (the board's sample periods)");
  a.sample_period_us = static_cast<std::uint32_t>(period);
  a.seconds = Number(body["seconds"], "seconds");
  Require(a.seconds > 0.0 && a.seconds <= kMaxSeconds, "'seconds' must lie in (0, 86400]");
  Require(a.seconds * 1e6 / a.sample_period_us >= 1.0,
          "'seconds' is shorter than one sample period");
  if (body.contains("log_rate_hz")) {
    const nlohmann::json& r = body["log_rate_hz"];
    if (r.is_string() && r.get<std::string>() == "auto") {
      a.auto_log_rate = true;
    } else {
      Require(r.is_number(), "'log_rate_hz' must be a rate in Hz or \"auto\"");
      a.log_rate_hz = Number(r, "log_rate_hz");
      Require(a.log_rate_hz > 0.0, "'log_rate_hz' must be > 0 (or \"auto\")");
      const double rate_hz = 1e6 / a.sample_period_us;
      const double d = rate_hz / a.log_rate_hz;
      const long n = std::lround(d);
      Require(n >= 1 && n <= static_cast<long>(fixed::kDecimatorMaxFactor) &&
                  std::abs(d - static_cast<double>(n)) < 1e-9 * d &&
                  fixed::IsSupportedDecimation(static_cast<std::uint32_t>(n)),
              "'log_rate_hz' " + Text(a.log_rate_hz) + ": the sample rate " + Text(rate_hz) +
                  " Hz divided by 2^a 5^b up to " + std::to_string(fixed::kDecimatorMaxFactor) +
                  " (the board's decimations), or \"auto\"");
      Require(a.seconds * a.log_rate_hz >= 1.0, "'seconds' is shorter than one logged record");
    }
  }
  const nlohmann::json& ch = body["channels"];
  Require(ch.is_array() && !ch.empty(), "'channels' must be a non-empty list of channel names");
  for (const nlohmann::json& name : ch) {
    Require(name.is_string(), "'channels' must list channel names");
    wire::Channel c{};
    Require(device::ChannelFromStem(name.get<std::string>(), c),
            "'channels': unknown channel '" + name.get<std::string>() +
                "' (force1, force2, acc1, acc2, x1, x2)");
    const auto bit = static_cast<std::uint8_t>(1u << static_cast<unsigned>(c));
    Require((a.channel_mask & bit) == 0,
            "'channels' names '" + name.get<std::string>() + "' twice");
    a.channel_mask = static_cast<std::uint8_t>(a.channel_mask | bit);
  }
  if (body.contains("log_dob")) {
    Require(body["log_dob"].is_boolean(), "'log_dob' must be true or false");
    a.log_dob = body["log_dob"].get<bool>();
  }
  if (body.contains("scenario")) {
    Require(body["scenario"].is_string(), "'scenario' must be a string");
    a.scenario = body["scenario"].get<std::string>();
    Require(!a.scenario.empty() && a.scenario.size() <= 16,
            "'scenario' must have 1 to 16 characters");
  }
  if (body.contains("scenario_params")) {
    const nlohmann::json& sp = body["scenario_params"];
    Require(sp.is_array() && sp.size() <= 4,
            "'scenario_params' must be a list of at most 4 numbers");
    Require(!a.scenario.empty(), "'scenario_params' needs a 'scenario'");
    for (const nlohmann::json& v : sp) {
      const double x = Number(v, "scenario_params");
      Require(std::abs(x) <= 3.4e38, "'scenario_params' holds a value beyond a float");
      a.scenario_params.push_back(static_cast<float>(x));
    }
  }
  if (body.contains("fit_measured")) {
    Require(body["fit_measured"].is_string(), "'fit_measured' must be a load cell name");
    a.fit_measured = body["fit_measured"].get<std::string>();
    wire::Channel c{};
    Require(device::ChannelFromStem(a.fit_measured, c) &&
                wire::IsLoadCell(static_cast<std::uint8_t>(c)),
            "'fit_measured': '" + a.fit_measured + "' is not a load cell (force1, force2)");
    Require((a.channel_mask & (1u << static_cast<unsigned>(c))) != 0,
            "'fit_measured': '" + a.fit_measured + "' is not among 'channels'");
    Require(a.log_dob, "'fit_measured' needs 'log_dob': the fit compares the observer's d̂");
  }
  if (body.contains("fit_lowpass_hz")) {
    a.fit_lowpass_hz = Number(body["fit_lowpass_hz"], "fit_lowpass_hz");
    // Below half the log rate where it is known; an automatic one is checked when it is chosen.
    const double nyquist_hz =
        0.5 * (a.log_rate_hz > 0.0 ? a.log_rate_hz : 1e6 / a.sample_period_us);
    Require(a.fit_lowpass_hz >= 0.0 && a.fit_lowpass_hz < nyquist_hz,
            "'fit_lowpass_hz' must lie in [0, " + std::to_string(nyquist_hz) +
                ") Hz (0: the raw d̂; below half the sample rate)");
    Require(a.fit_lowpass_hz == 0.0 || !a.fit_measured.empty(),
            "'fit_lowpass_hz' needs 'fit_measured'");
  }
  return a;
}

wire::AcqConfigureRequest ConfigFor(const AcquisitionAsk& ask, const wire::InfoResponse& info) {
  wire::AcqConfigureRequest cfg;
  cfg.sample_period_us = ask.sample_period_us;
  cfg.channel_mask = ask.channel_mask;
  cfg.flags =
      static_cast<std::uint8_t>(wire::kAcqFlagStream | (ask.log_dob ? wire::kAcqFlagLogDob : 0));
  const double rate_hz = 1e6 / static_cast<double>(ask.sample_period_us);
  cfg.decimation = 1;
  if (ask.auto_log_rate) {
    cfg.decimation = std::max<std::uint16_t>(1, device::DecimationThatFits(info, cfg, ask.seconds));
  } else if (ask.log_rate_hz > 0.0) {
    cfg.decimation = static_cast<std::uint16_t>(std::lround(rate_hz / ask.log_rate_hz));
  }
  cfg.record_limit = static_cast<std::uint32_t>(std::max<long long>(
      1, std::llround(ask.seconds * rate_hz / static_cast<double>(cfg.decimation))));
  return cfg;
}

}  // namespace vibid::bench
