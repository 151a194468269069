// CRC-32 as used by Ethernet, zlib and PNG (ISO-HDLC): polynomial 0x04C11DB7 reflected
// (0xEDB88320), initial value and final XOR 0xFFFFFFFF. Check value: "123456789" -> 0xCBF43926.
#pragma once

#include <cstdint>
#include <span>

namespace vibid::wire {

/// Incremental CRC-32: feed bytes in any number of pieces, read value() at any point.
class Crc32 {
 public:
  void Update(std::span<const std::uint8_t> bytes);
  std::uint32_t value() const { return ~state_; }

 private:
  std::uint32_t state_ = 0xFFFFFFFFu;
};

/// CRC-32 of one buffer.
std::uint32_t ComputeCrc32(std::span<const std::uint8_t> bytes);

}  // namespace vibid::wire
