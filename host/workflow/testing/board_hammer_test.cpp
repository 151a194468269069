#include "testing/board_hammer_test.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include <nlohmann/json.hpp>

#include "vibid/common/json_file.hpp"
#include "vibid/device/calibration_builder.hpp"
#include "vibid/ident/testing/hammer_test.hpp"
#include "vibid/model/model_json.hpp"

namespace vibid::workflow::testing {

BoardHammerTest MakeBoardHammerTest(const std::string& live_csv_path, double record_s) {
  const std::string root = VIBID_SOURCE_DIR;
  const model::Model rig = model::LoadModel(root + "/examples/rig_nominal.json");
  ident::HammerTestSpec spec;
  spec.hammer_dof = 1;
  spec.fs_hz = 5000.0;
  spec.oversample = 4;
  spec.hits = 10;
  spec.hit_peak_n = 100.0;
  spec.hit_peak_spread = 0.2;
  spec.pulse_width_s = 0.004;
  spec.spacing_min_s = record_s + 1.0;
  spec.spacing_max_s = record_s + 1.5;
  spec.lead_s = 0.5;
  spec.tail_s = 0.5 * record_s;
  spec.force_noise = 0.0005;
  spec.response_noise = 0.0005;
  spec.seed = 7;
  spec.changes = {{.hit = 2, .second_delay_s = 0.012, .second_fraction = 0.6},
                  {.hit = 4, .scale = 6.0},
                  {.hit = 6, .scale = 0.2}};
  const ident::HammerTestRecord rec = ident::SimulateHammerTest(rig, spec);

  BoardHammerTest out;
  out.hit_times_s = rec.hit_times_s;
  HammerSessionOptions& o = out.options;
  const std::uint8_t mask = (1u << static_cast<unsigned>(wire::Channel::kForce1)) |
                            (1u << static_cast<unsigned>(wire::Channel::kAccel1)) |
                            (1u << static_cast<unsigned>(wire::Channel::kAccel2));
  o.layout.channel_mask = mask;
  o.layout.flags = 0;
  o.sample_period_us = 200;
  o.decimation = 1;
  const device::SensorSet sensors =
      device::SensorsFromJson(ReadJsonFile(root + "/examples/sensors.json"), "sensors.json");
  o.has_calibration = true;
  for (std::size_t c = 0; c < wire::kChannelCount; ++c) {
    if (sensors[c]) o.calibration.channels[c] = device::ToChannelScaling(*sensors[c], "channel");
  }
  wire::SamplingInfoResponse instants;
  instants.sample_instant_ns = {2667, 5905, 9143, 12381, 0, 0};
  o.instants = instants;
  o.estimation.force = "force1_n";
  o.estimation.responses = "acc1_m_s2,acc2_m_s2";
  o.estimation.impact_options.record_s = record_s;
  o.estimation.impact_options.trigger_fraction = 0.02;
  o.estimation.impact_options.exp_window_end = 0.01;
  o.modes.driving_point = "acc2_m_s2";
  o.live_csv_path = live_csv_path;

  // Converter codes (12 bits, 4 fraction bits in the log) of each channel's SI value.
  const auto code = [&](wire::Channel c, double value) {
    const device::SensorScaling& s = *sensors[static_cast<std::size_t>(c)];
    const double counts = static_cast<double>(s.offset_counts) + value * s.counts_per_unit;
    const long clipped = std::clamp(std::lround(counts), 0L, 4095L);
    return static_cast<std::int32_t>(clipped << wire::kLogAdcFractionBits);
  };
  out.records.resize(static_cast<std::size_t>(rec.force_n.size()));
  for (Eigen::Index i = 0; i < rec.force_n.size(); ++i) {
    wire::LogRecord& r = out.records[static_cast<std::size_t>(i)];
    r.sample_index = static_cast<std::uint32_t>(i);
    r.raw[static_cast<std::size_t>(wire::Channel::kForce1)] =
        code(wire::Channel::kForce1, rec.force_n[i]);
    r.raw[static_cast<std::size_t>(wire::Channel::kAccel1)] =
        code(wire::Channel::kAccel1, rec.response(i, 0));
    r.raw[static_cast<std::size_t>(wire::Channel::kAccel2)] =
        code(wire::Channel::kAccel2, rec.response(i, 1));
  }
  return out;
}

void FeedInBlocks(HammerSession& session, const std::vector<wire::LogRecord>& records,
                  std::uint64_t seed, std::size_t max_block) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::size_t> size(1, max_block);
  for (std::size_t at = 0; at < records.size();) {
    const std::size_t n = std::min(size(rng), records.size() - at);
    session.Feed(std::span<const wire::LogRecord>(records.data() + at, n));
    at += n;
  }
}

}  // namespace vibid::workflow::testing
