#include "vibid/shared/wire/crc32.hpp"

#include <array>

namespace vibid::wire {
namespace {

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

constexpr std::array<std::uint32_t, 256> kTable = MakeTable();

}  // namespace

void Crc32::Update(std::span<const std::uint8_t> bytes) {
  std::uint32_t c = state_;
  for (const std::uint8_t b : bytes) c = kTable[(c ^ b) & 0xFFu] ^ (c >> 8);
  state_ = c;
}

std::uint32_t ComputeCrc32(std::span<const std::uint8_t> bytes) {
  Crc32 crc;
  crc.Update(bytes);
  return crc.value();
}

}  // namespace vibid::wire
