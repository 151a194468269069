#include "vibid/shared/wire/serial_frame.hpp"

#include <algorithm>

#include "vibid/shared/wire/crc32.hpp"

namespace vibid::wire {
namespace {

constexpr std::size_t kOffLength = 2;
constexpr std::size_t kOffReport = 3;
constexpr std::size_t kOffCrc = kOffReport + kReportBytes;

std::uint32_t FrameCrc(std::span<const std::uint8_t> frame) {
  return wire::ComputeCrc32(frame.subspan(kOffLength, 1 + kReportBytes));
}

}  // namespace

SerialFrameBytes EncodeSerialFrame(std::span<const std::uint8_t, kReportBytes> report) {
  SerialFrameBytes f{};
  f[0] = kSerialSync0;
  f[1] = kSerialSync1;
  f[kOffLength] = static_cast<std::uint8_t>(kReportBytes);
  std::copy(report.begin(), report.end(), f.begin() + kOffReport);
  const std::uint32_t crc = FrameCrc(f);
  for (std::size_t i = 0; i < 4; ++i) f[kOffCrc + i] = static_cast<std::uint8_t>(crc >> (8 * i));
  return f;
}

void SerialFrameDecoder::Resync(std::size_t drop) {
  // Keep the longest tail that could still be the start of a frame.
  std::size_t start = drop;
  while (start < fill_) {
    if (buffer_[start] == kSerialSync0 &&
        (start + 1 == fill_ || buffer_[start + 1] == kSerialSync1))
      break;
    ++start;
  }
  counters_.skipped_bytes += static_cast<std::uint32_t>(start);
  std::copy(buffer_.begin() + static_cast<std::ptrdiff_t>(start),
            buffer_.begin() + static_cast<std::ptrdiff_t>(fill_), buffer_.begin());
  fill_ -= start;
}

bool SerialFrameDecoder::Push(std::uint8_t byte, Report& report) {
  buffer_[fill_++] = byte;
  // Header checks as soon as the bytes are there, so garbage is dropped early.
  if (buffer_[0] != kSerialSync0 || (fill_ > 1 && buffer_[1] != kSerialSync1) ||
      (fill_ > kOffLength && buffer_[kOffLength] != kReportBytes)) {
    Resync(1);
    return false;
  }
  if (fill_ < kSerialFrameBytes) return false;
  std::uint32_t crc = 0;
  for (std::size_t i = 0; i < 4; ++i)
    crc |= static_cast<std::uint32_t>(buffer_[kOffCrc + i]) << (8 * i);
  if (crc != FrameCrc(buffer_)) {
    ++counters_.crc_errors;
    Resync(1);
    return false;
  }
  std::copy_n(buffer_.begin() + kOffReport, kReportBytes, report.begin());
  fill_ = 0;
  ++counters_.frames;
  return true;
}

}  // namespace vibid::wire
