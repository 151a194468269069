// The QEMU image's report link: 64-byte reports framed (serial_frame.hpp) on USART1.
//
// Receive: the RXNE interrupt moves bytes into a ring; Receive() (main loop) runs them through
// the frame decoder. When the ring is full the interrupt is masked and the byte stays in the
// data register, which holds the sender off (QEMU's USART accepts no new byte while RXNE is set),
// so nothing is lost however slowly the main loop runs. Send: the 71 frame bytes go out through
// the data register, waiting on TXE.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

#include "vibid/shared/wire/serial_frame.hpp"
#include "vibid/fw/report_link.hpp"

namespace vibid::fw::qemu {

class UsartReportLink final : public ReportLink {
 public:
  /// USART1 at `baud` from a `pclk_hz` peripheral clock (the baud rate matters on silicon only;
  /// QEMU delivers bytes as fast as the socket does).
  void Init(std::uint32_t pclk_hz, std::uint32_t baud);

  Status Receive(wire::Report& out) override;
  Status Send(const wire::Report& report) override;

  const wire::SerialFrameCounters& DecoderCounters() const { return decoder_.counters(); }

  /// The USART1 interrupt handler body.
  void HandleInterrupt();

 private:
  static constexpr std::size_t kRingBytes = 256;  // Power of two.

  std::array<std::uint8_t, kRingBytes> ring_{};
  std::atomic<std::uint32_t> head_{0};  ///< Written by the interrupt.
  std::atomic<std::uint32_t> tail_{0};  ///< Written by the main loop.
  wire::SerialFrameDecoder decoder_;
};

}  // namespace vibid::fw::qemu
