// Memory-mapped register access for the STM32F405 port. The register headers beside this file
// hold addresses and bit positions written from RM0090 (STM32F405/415 reference manual, rev 19)
// and the Cortex-M4 generic user guide; no vendor headers are used.
#pragma once

#include <cstdint>

namespace vibid::fw::stm32 {

using Address = std::uintptr_t;

inline volatile std::uint32_t& Reg(Address address) {
  return *reinterpret_cast<volatile std::uint32_t*>(address);
}
inline volatile std::uint8_t& Reg8(Address address) {
  return *reinterpret_cast<volatile std::uint8_t*>(address);
}

constexpr std::uint32_t Bit(unsigned n) { return 1U << n; }
/// A field value `v` placed at bit `pos`.
constexpr std::uint32_t Field(std::uint32_t v, unsigned pos) { return v << pos; }

/// Read-modify-write of the bits in `mask`.
inline void Modify(Address address, std::uint32_t mask, std::uint32_t value) {
  Reg(address) = (Reg(address) & ~mask) | (value & mask);
}

/// Polls until (reg & mask) == want or `max_polls` reads have been made.
/// @returns true when the condition was met.
inline bool WaitFor(Address address, std::uint32_t mask, std::uint32_t want, std::uint32_t max_polls) {
  for (std::uint32_t i = 0; i < max_polls; ++i) {
    if ((Reg(address) & mask) == want) return true;
  }
  return false;
}

}  // namespace vibid::fw::stm32
