// Memory-mapped register access for the STM32F405 port. The register headers beside this file
// hold addresses and bit positions written from RM0090 (STM32F405/415 reference manual, rev 19)
// and the Cortex-M4 generic user guide; no vendor headers are used.
//
// On the target Reg() is a volatile reference to the address. A host build of the port's tests
// defines VIBID_STM32_FAKE_REGISTERS: Reg() then returns a small proxy that forwards every read
// and write to a fake register file (testing/fake_registers.hpp), which logs the sequence and
// models the few hardware reactions a test needs. The driver code is the same in both builds.
#pragma once

#include <cstdint>

namespace vibid::fw::stm32 {

using Address = std::uintptr_t;

constexpr std::uint32_t Bit(unsigned n) { return 1U << n; }
/// A field value `v` placed at bit `pos`.
constexpr std::uint32_t Field(std::uint32_t v, unsigned pos) { return v << pos; }

#if defined(VIBID_STM32_FAKE_REGISTERS)

namespace fake {
/// Implemented by the test's register file. `width_bytes` is 1 or 4.
std::uint32_t Read(Address address, unsigned width_bytes);
void Write(Address address, std::uint32_t value, unsigned width_bytes);
}  // namespace fake

/// Stands in for `volatile std::uint32_t&` with the operators the drivers use.
class RegRef {
 public:
  constexpr RegRef(Address address, unsigned width_bytes)
      : address_(address), width_(width_bytes) {}
  operator std::uint32_t() const {
    return fake::Read(address_, width_);
  }  // NOLINT: mimics a reference
  const RegRef& operator=(std::uint32_t v) const {
    fake::Write(address_, v, width_);
    return *this;
  }
  // `Reg(a) = Reg(b)` copies the value, as with references, not the proxy.
  const RegRef& operator=(const RegRef& other) const {
    return *this = static_cast<std::uint32_t>(other);
  }
  RegRef(const RegRef&) = default;
  const RegRef& operator|=(std::uint32_t v) const {
    return *this = (fake::Read(address_, width_) | v);
  }
  const RegRef& operator&=(std::uint32_t v) const {
    return *this = (fake::Read(address_, width_) & v);
  }

 private:
  Address address_;
  unsigned width_;
};

inline RegRef Reg(Address address) { return RegRef(address, 4); }
inline RegRef Reg8(Address address) { return RegRef(address, 1); }

#else

inline volatile std::uint32_t& Reg(Address address) {
  return *reinterpret_cast<volatile std::uint32_t*>(address);
}
inline volatile std::uint8_t& Reg8(Address address) {
  return *reinterpret_cast<volatile std::uint8_t*>(address);
}

#endif

/// Read-modify-write of the bits in `mask`.
inline void Modify(Address address, std::uint32_t mask, std::uint32_t value) {
  Reg(address) = (Reg(address) & ~mask) | (value & mask);
}

/// Polls until (reg & mask) == want or `max_polls` reads have been made.
/// @returns true when the condition was met.
inline bool WaitFor(Address address, std::uint32_t mask, std::uint32_t want,
                    std::uint32_t max_polls) {
  for (std::uint32_t i = 0; i < max_polls; ++i) {
    if ((Reg(address) & mask) == want) return true;
  }
  return false;
}

}  // namespace vibid::fw::stm32
