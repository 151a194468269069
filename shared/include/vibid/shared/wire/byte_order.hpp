// Explicit little-endian loads and stores. The wire never depends on the host's byte order or on
// struct layout: every field is read and written through these, at its documented offset.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

namespace vibid::wire {

constexpr void StoreU8(std::span<std::uint8_t> out, std::size_t offset, std::uint8_t v) {
  out[offset] = v;
}
constexpr void StoreU16(std::span<std::uint8_t> out, std::size_t offset, std::uint16_t v) {
  out[offset] = static_cast<std::uint8_t>(v);
  out[offset + 1] = static_cast<std::uint8_t>(v >> 8);
}
constexpr void StoreU32(std::span<std::uint8_t> out, std::size_t offset, std::uint32_t v) {
  for (std::size_t i = 0; i < 4; ++i) out[offset + i] = static_cast<std::uint8_t>(v >> (8 * i));
}
constexpr void StoreU64(std::span<std::uint8_t> out, std::size_t offset, std::uint64_t v) {
  for (std::size_t i = 0; i < 8; ++i) out[offset + i] = static_cast<std::uint8_t>(v >> (8 * i));
}
constexpr void StoreI32(std::span<std::uint8_t> out, std::size_t offset, std::int32_t v) {
  StoreU32(out, offset, static_cast<std::uint32_t>(v));
}
constexpr void StoreI64(std::span<std::uint8_t> out, std::size_t offset, std::int64_t v) {
  StoreU64(out, offset, static_cast<std::uint64_t>(v));
}

constexpr std::uint8_t LoadU8(std::span<const std::uint8_t> in, std::size_t offset) {
  return in[offset];
}
constexpr std::uint16_t LoadU16(std::span<const std::uint8_t> in, std::size_t offset) {
  return static_cast<std::uint16_t>(in[offset] | (in[offset + 1] << 8));
}
constexpr std::uint32_t LoadU32(std::span<const std::uint8_t> in, std::size_t offset) {
  std::uint32_t v = 0;
  for (std::size_t i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(in[offset + i]) << (8 * i);
  return v;
}
constexpr std::uint64_t LoadU64(std::span<const std::uint8_t> in, std::size_t offset) {
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < 8; ++i) v |= static_cast<std::uint64_t>(in[offset + i]) << (8 * i);
  return v;
}
constexpr std::int32_t LoadI32(std::span<const std::uint8_t> in, std::size_t offset) {
  return static_cast<std::int32_t>(LoadU32(in, offset));
}
constexpr std::int64_t LoadI64(std::span<const std::uint8_t> in, std::size_t offset) {
  return static_cast<std::int64_t>(LoadU64(in, offset));
}

}  // namespace vibid::wire
