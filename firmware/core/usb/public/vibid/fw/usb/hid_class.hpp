// HID class driver (HID 1.11) for the board's vendor interface: 64-byte input reports on the
// interrupt IN endpoint, 64-byte output reports from the interrupt OUT endpoint or SET_REPORT.
// No boot protocol (GET/SET_PROTOCOL stall), no report ids, no feature reports.
//
// It is the board's ReportLink: the command server reads output reports with Receive and answers
// with Send.
//
// Flow control: received reports wait in a two-slot queue; the OUT endpoint is armed only while a
// slot is free, so a slow reader makes the host see NAKs, never a lost report.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "vibid/fw/usb/class_driver.hpp"
#include "vibid/fw/report_link.hpp"
#include "vibid/fw/usb/descriptors.hpp"
#include "vibid/shared/wire/report.hpp"

namespace vibid::fw::usb {

/// HID class request codes (HID 1.11 §7.2).
enum class HidRequest : std::uint8_t {
  kGetReport = 0x01,
  kGetIdle = 0x02,
  kGetProtocol = 0x03,
  kSetReport = 0x09,
  kSetIdle = 0x0A,
  kSetProtocol = 0x0B,
};
/// Report types in the high byte of wValue of GET/SET_REPORT (HID 1.11 §7.2.1).
enum class HidReportType : std::uint8_t { kInput = 1, kOutput = 2, kFeature = 3 };

struct HidCounters {
  std::uint32_t reports_in = 0;     ///< Input reports the host collected.
  std::uint32_t reports_out = 0;    ///< Output reports received (endpoint or SET_REPORT).
  std::uint32_t short_reports = 0;  ///< OUT packets shorter than a report, discarded.
};

class HidClass final : public ClassDriver, public ReportLink {
 public:
  using Report = wire::Report;
  static_assert(wire::kReportBytes == kHidReportSize, "one wire report per HID report");

  /// True when configured and the IN endpoint can take a report now.
  bool CanSend() const { return open_ && !tx_busy_; }
  /// Queues one input report for the next IN poll.
  /// @returns kOk; kUnavailable while the previous report is still in flight or the host has
  ///          not configured the device (nothing taken: offer it again later).
  Status Send(const wire::Report& report) override;
  /// Takes the oldest received output report.
  /// @returns kOk with `out` filled; kUnavailable when none is waiting.
  Status Receive(wire::Report& out) override;
  bool is_open() const { return open_; }
  std::uint8_t idle_rate() const { return idle_rate_; }
  const HidCounters& counters() const { return counters_; }

  // ClassDriver
  bool OwnsInterface(std::uint8_t interface_number) const override;
  bool OwnsEndpoint(std::uint8_t ep_addr) const override;
  Status Open(Dcd& dcd) override;
  void Close() override;
  ControlReply OnControlRequest(const SetupPacket& setup, std::span<std::uint8_t> scratch) override;
  bool OnControlData(const SetupPacket& setup, std::span<const std::uint8_t> data) override;
  void OnControlComplete(const SetupPacket& setup) override;
  void OnTransferComplete(std::uint8_t ep_addr, std::uint16_t length) override;
  void OnEndpointHalt(std::uint8_t ep_addr, bool halted) override;

 private:
  static constexpr std::size_t kRxSlots = 2;
  bool RxSlotFree() const { return rx_count_ + (out_armed_ ? 1U : 0U) < kRxSlots; }
  void PushRx(std::span<const std::uint8_t> report);
  void ArmOut();

  Dcd* dcd_ = nullptr;
  bool open_ = false;
  bool tx_busy_ = false;
  bool out_armed_ = false;
  bool out_halted_ = false;
  std::uint8_t idle_rate_ = 0;
  alignas(4) Report tx_buffer_{};
  alignas(4) Report last_input_{};  ///< What GET_REPORT(Input) answers: the latest report sent.
  alignas(4) Report out_buffer_{};
  std::array<Report, kRxSlots> rx_{};
  std::size_t rx_head_ = 0;
  std::size_t rx_count_ = 0;
  HidCounters counters_{};
};

}  // namespace vibid::fw::usb
