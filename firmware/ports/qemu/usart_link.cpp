#include "usart_link.hpp"

#include "regs/core_m4.hpp"
#include "regs/peripherals.hpp"
#include "regs/rcc.hpp"

namespace vibid::fw::qemu {

using namespace vibid::fw::stm32;

void UsartReportLink::Init(std::uint32_t pclk_hz, std::uint32_t baud) {
  // PA9 = TX, PA10 = RX, alternate function 7.
  Reg(rcc::kAhb1enr) |= rcc::kAhb1GpioA;
  Reg(rcc::kApb2enr) |= rcc::kApb2Usart1;
  gpio::SetAlternate(gpio::kPortA, 9, 7);
  gpio::SetAlternate(gpio::kPortA, 10, 7);
  // Oversampling by 16: BRR = pclk / baud, mantissa and fraction in one division.
  Reg(usart::kUsart1 + usart::kBrr) = (pclk_hz + baud / 2) / baud;
  Reg(usart::kUsart1 + usart::kCr1) =
      usart::kCr1Ue | usart::kCr1Te | usart::kCr1Re | usart::kCr1Rxneie;
  nvic::SetPriority(irq::kUsart1, 4);
  nvic::Enable(irq::kUsart1);
}

void UsartReportLink::HandleInterrupt() {
  const std::uint32_t head = head_.load(std::memory_order_relaxed);
  if (head - tail_.load(std::memory_order_acquire) >= kRingBytes) {
    // Full: leave the byte in DR (the sender waits) until Receive() makes room.
    Reg(usart::kUsart1 + usart::kCr1) &= ~usart::kCr1Rxneie;
    return;
  }
  if ((Reg(usart::kUsart1 + usart::kSr) & usart::kSrRxne) == 0) return;
  ring_[head % kRingBytes] = static_cast<std::uint8_t>(Reg(usart::kUsart1 + usart::kDr));
  head_.store(head + 1, std::memory_order_release);
}

Status UsartReportLink::Receive(wire::Report& out) {
  std::uint32_t tail = tail_.load(std::memory_order_relaxed);
  Status result = Status::kUnavailable;
  wire::Report report{};
  while (tail != head_.load(std::memory_order_acquire)) {
    const std::uint8_t byte = ring_[tail % kRingBytes];
    ++tail;
    if (decoder_.Push(byte, report)) {
      out = report;
      result = Status::kOk;
      break;
    }
  }
  tail_.store(tail, std::memory_order_release);
  Reg(usart::kUsart1 + usart::kCr1) |= usart::kCr1Rxneie;
  return result;
}

Status UsartReportLink::Send(const wire::Report& report) {
  const wire::SerialFrameBytes frame = wire::EncodeSerialFrame(report);
  for (std::uint8_t b : frame) {
    while ((Reg(usart::kUsart1 + usart::kSr) & usart::kSrTxe) == 0) {
    }
    Reg(usart::kUsart1 + usart::kDr) = b;
  }
  return Status::kOk;
}

}  // namespace vibid::fw::qemu
