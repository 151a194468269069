#include "diagnostics.hpp"

#include <array>

#include "regs/peripherals.hpp"
#include "regs/rcc.hpp"

namespace vibid::fw::qemu {

using namespace vibid::fw::stm32;

namespace {
constexpr Address kUsart2 = 0x40004400;
constexpr std::uint32_t kApb1Usart2 = Bit(17);

void Put(char c) {
  while ((Reg(kUsart2 + usart::kSr) & usart::kSrTxe) == 0) {
  }
  Reg(kUsart2 + usart::kDr) = static_cast<std::uint8_t>(c);
}

void PutText(const char* text) {
  while (*text != '\0') Put(*text++);
}

void PutNumber(std::uint64_t v) {
  std::array<char, 20> digits{};
  int n = 0;
  do {
    digits[static_cast<std::size_t>(n++)] = static_cast<char>('0' + v % 10);
    v /= 10;
  } while (v != 0);
  while (n > 0) Put(digits[static_cast<std::size_t>(--n)]);
}

}  // namespace

void DiagnosticsInit() {
  Reg(rcc::kApb1enr) |= kApb1Usart2;
  Reg(kUsart2 + usart::kBrr) = 42000000 / 115200;  // APB1 42 MHz on silicon; QEMU ignores it.
  Reg(kUsart2 + usart::kCr1) = usart::kCr1Ue | usart::kCr1Te;
}

void DiagnosticsLine(const char* text) {
  PutText(text);
  Put('\n');
}

void DiagnosticsValues(const char* const* labels, const std::uint64_t* values, int count) {
  for (int i = 0; i < count; ++i) {
    if (i > 0) Put(' ');
    PutText(labels[i]);
    Put(' ');
    PutNumber(values[i]);
  }
  Put('\n');
}

}  // namespace vibid::fw::qemu
