// Access to the golden wire vectors (shared/wire/testdata/wire_vectors.txt), embedded into the
// test image at build time so the same lookups work on the host and on the Cortex-M4 under QEMU.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "vibid/shared/wire/report.hpp"

namespace vibid::wire::testing {

/// Largest vector in the file (the calibration record).
inline constexpr std::size_t kMaxVectorBytes = 1024;

/// Decodes the hex bytes of vector `name` into `out`.
/// @returns the byte count, or 0 if the name is missing, the hex is malformed or too long.
std::size_t GoldenVector(std::string_view name, std::span<std::uint8_t> out);

/// A 64-byte report vector; an all-zero report if the vector is missing or not 64 bytes.
Report GoldenReport(std::string_view name);

/// The integer value of a `key value` line (protocol_major, ...), or -1 if missing.
long GoldenConstant(std::string_view name);

}  // namespace vibid::wire::testing
