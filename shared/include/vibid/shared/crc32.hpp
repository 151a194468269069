// CRC-32 as used by Ethernet, zlib and PNG (ISO-HDLC): polynomial 0x04C11DB7 reflected
// (0xEDB88320), initial value and final XOR 0xFFFFFFFF. Check value: "123456789" -> 0xCBF43926.
// One implementation for every checksum in shared/: the wire records, the serial framing and the
// fixed-point filter description.
#pragma once

#include <array>
#include <cstdint>
#include <span>

namespace vibid {
namespace crc32_detail {

// Byte-at-a-time table (1 KiB of flash): a log pull computes the CRC of every streamed byte,
// and the bitwise loop would cost eight iterations per byte on the board.
constexpr std::array<std::uint32_t, 256> MakeTable() {
  std::array<std::uint32_t, 256> table{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int bit = 0; bit < 8; ++bit) c = (c & 1u) != 0 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    table[i] = c;
  }
  return table;
}

inline constexpr std::array<std::uint32_t, 256> kTable = MakeTable();

}  // namespace crc32_detail

/// Incremental CRC-32: feed bytes in any number of pieces, read value() at any point.
class Crc32 {
 public:
  constexpr void Update(std::span<const std::uint8_t> bytes) {
    std::uint32_t c = state_;
    for (const std::uint8_t b : bytes) c = crc32_detail::kTable[(c ^ b) & 0xFFu] ^ (c >> 8);
    state_ = c;
  }
  constexpr std::uint32_t value() const { return ~state_; }

 private:
  std::uint32_t state_ = 0xFFFFFFFFu;
};

/// CRC-32 of one buffer.
constexpr std::uint32_t ComputeCrc32(std::span<const std::uint8_t> bytes) {
  Crc32 crc;
  crc.Update(bytes);
  return crc.value();
}

}  // namespace vibid
