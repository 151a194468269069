#include "vibid/device/info_json.hpp"

#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "vibid/common/enum_names.hpp"
#include "vibid/device/watch_report.hpp"
#include "vibid/device/health_report.hpp"
#include "vibid/device/log_table.hpp"
#include "vibid/shared/wire/log_record.hpp"

namespace vibid::device {
namespace {

constexpr EnumNames<wire::BoardId, 4> kBoardNames{{
    {wire::BoardId::kStm32f405, "stm32f405"},
    {wire::BoardId::kQemuNetduinoPlus2, "qemu-netduinoplus2"},
    {wire::BoardId::kEmulator, "emulator"},
    {wire::BoardId::kHostTest, "host-test"},
}};

constexpr EnumNames<wire::ResetCause, 8> kResetNames{{
    {wire::ResetCause::kUnknown, "unknown"},
    {wire::ResetCause::kPowerOn, "power-on"},
    {wire::ResetCause::kPin, "reset-pin"},
    {wire::ResetCause::kSoftware, "software"},
    {wire::ResetCause::kWatchdog, "watchdog"},
    {wire::ResetCause::kBrownOut, "brown-out"},
    {wire::ResetCause::kLowPower, "low-power"},
    {wire::ResetCause::kFault, "fault"},
}};

}  // namespace

const char* BoardName(wire::BoardId board) { return NameOf(kBoardNames, board, "unknown"); }

namespace {

std::vector<std::string> CapabilityNames(std::uint32_t caps) {
  std::vector<std::string> out;
  const std::pair<std::uint32_t, const char*> names[] = {
      {wire::kCapDob, "dob"},
      {wire::kCapForceTrigger, "force-trigger"},
      {wire::kCapDfu, "dfu"},
      {wire::kCapScenarioSelect, "scenario-select"},
      {wire::kCapSampleInjection, "sample-injection"}};
  for (const auto& [bit, name] : names) {
    if ((caps & bit) != 0) out.emplace_back(name);
  }
  return out;
}

std::string Hex32(std::uint32_t v) {
  char b[11];
  std::snprintf(b, sizeof(b), "0x%08x", v);
  return b;
}

/// Clipped samples per channel of the last acquisition; null from a 2.0 board.
nlohmann::json ClipsJson(const std::optional<wire::ClipResponse>& clips) {
  if (!clips) return nullptr;
  nlohmann::json per_channel = nlohmann::json::object();
  for (std::size_t k = 0; k < wire::kChannelCount; ++k)
    per_channel[ChannelStem(static_cast<wire::Channel>(k))] = clips->clipped[k];
  return {{"samples", clips->ticks}, {"channels", per_channel}};
}

}  // namespace

/// The fault record after a fault reset; null without one.
nlohmann::json FaultJson(const std::optional<wire::FaultInfoResponse>& fault) {
  if (!fault || fault->recorded == 0) return nullptr;
  const bool stacked =
      !(fault->pc == wire::kFaultNoStackedValue && fault->lr == wire::kFaultNoStackedValue);
  return {{"exception", fault->exception},
          {"exception_name", FaultExceptionName(fault->exception)},
          {"cfsr", Hex32(fault->cfsr)},
          {"hfsr", Hex32(fault->hfsr)},
          {"mmfar", Hex32(fault->mmfar)},
          {"bfar", Hex32(fault->bfar)},
          {"pc", stacked ? nlohmann::json(Hex32(fault->pc)) : nlohmann::json(nullptr)},
          {"lr", stacked ? nlohmann::json(Hex32(fault->lr)) : nlohmann::json(nullptr)},
          {"status", FaultStatusNames(*fault)},
          {"text", FaultText(*fault)}};
}

nlohmann::json InfoJson(const device::Connection& c, const wire::InfoResponse& i,
                        const std::optional<wire::ClipResponse>& clips,
                        const std::optional<wire::SamplingInfoResponse>& sampling,
                        const std::optional<wire::HealthInfoResponse>& health,
                        const std::optional<wire::WatchInfoResponse>& watch,
                        const std::optional<wire::FaultInfoResponse>& fault) {
  // Channel -> us after the timer edge; null for a board of protocol 2.0, which does not say.
  nlohmann::json instants = nullptr;
  if (sampling) {
    instants = nlohmann::json::object();
    for (std::size_t k = 0; k < wire::kChannelCount; ++k) {
      instants[ChannelStem(static_cast<wire::Channel>(k))] =
          sampling->sample_instant_ns[k] / 1000.0;
    }
  }
  nlohmann::json channels = nlohmann::json::array();
  nlohmann::json formats = nlohmann::json::object();
  for (std::size_t k = 0; k < wire::kChannelCount; ++k) {
    const auto ch = static_cast<wire::Channel>(k);
    channels.push_back(ChannelStem(ch));
    formats[ChannelStem(ch)] = wire::LogValueBytes(ch) == 2
                                   ? "u16 " + std::to_string(i.adc_bits) + "." +
                                         std::to_string(wire::kLogAdcFractionBits) + " ADC code"
                                   : std::string("i32 counts");
  }
  return {
      {"device", c.Describe()},
      {"protocol", std::to_string(i.protocol_major) + "." + std::to_string(i.protocol_minor)},
      {"firmware", std::to_string(i.fw_major) + "." + std::to_string(i.fw_minor) + "." +
                       std::to_string(i.fw_patch)},
      {"build_id", Hex32(i.build_id)},
      {"board", NameOf(kBoardNames, i.board_id, "unknown")},
      {"capabilities", CapabilityNames(i.capabilities)},
      {"sample_period_us", i.sample_period_us},
      {"min_sample_period_us", i.min_sample_period_us},
      {"log_capacity_bytes", i.log_capacity_bytes},
      {"log_bytes", i.log_capacity_bytes},
      {"link_reports_per_s", i.link_reports_per_s},
      {"report_bytes", wire::kReportBytes},
      {"link_bytes_per_s", std::uint32_t{i.link_reports_per_s} * wire::kReportBytes},
      {"link_record_bytes_per_s", std::uint32_t{i.link_reports_per_s} * wire::kLogRecordPayload},
      {"max_sample_rate_hz", 1e6 / i.min_sample_period_us},
      {"adc_bits", i.adc_bits},
      {"channels", channels},
      {"channel_formats", formats},
      {"sample_instants_us", instants},
      {"reset_cause", NameOf(kResetNames, i.reset_cause, "unknown")},
      // What the fault handler recorded when reset_cause is "fault"; null otherwise.
      {"fault", FaultJson(fault)},
      // "level3" .. "off", "unknown" when the board does not say (also a 2.0 board).
      {"brown_out_level", BrownOutName(health ? health->brown_out : wire::BrownOut::kUnknown)},
      // "crystal", "crystal-wrong-frequency", ..., "unknown" when the board does not say.
      {"clock", ClockStateName(health ? static_cast<std::uint32_t>(health->clock) : 0)},
      {"clock_text", health && ClockText(*health) ? nlohmann::json(*ClockText(*health))
                                                  : nlohmann::json(nullptr)},
      {"hse_measured_hz", health && health->hse_measured_hz != 0
                              ? nlohmann::json(health->hse_measured_hz)
                              : nlohmann::json(nullptr)},
      {"sampler_recoveries",
       health ? nlohmann::json(health->sampler_recoveries) : nlohmann::json(nullptr)},
      {"calibrated", i.cal_state == wire::CalState::kCalibrated},
      {"cal_slot",
       i.cal_slot == wire::kNoSlot ? nlohmann::json(nullptr) : nlohmann::json(i.cal_slot)},
      {"cal_crc", Hex32(i.cal_crc)},
      {"overrun_count", i.overrun_count},
      {"dropped_records", i.dropped_records},
      {"clipped", ClipsJson(clips)},
      {"model_stale", WatchJson(watch, i.sample_period_us)}};
}

}  // namespace vibid::device
