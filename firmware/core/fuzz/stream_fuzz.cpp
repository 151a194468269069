// Fuzzes the host-side stream decoder with arbitrary reports: it must never accept a stream
// whose trailer does not match what it was fed, and never read past a report.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "vibid/shared/wire/crc32.hpp"
#include "vibid/shared/wire/stream.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace vibid;
  if (size < 3) return 0;
  const auto command = static_cast<wire::Command>(data[0]);
  const auto token = static_cast<std::uint16_t>(data[1] | data[2] << 8);
  wire::StreamDecoder decoder(command, token);
  wire::Crc32 crc;
  std::uint32_t bytes = 0;
  for (std::size_t offset = 3; offset < size; offset += wire::kReportBytes) {
    wire::Report report{};
    std::memcpy(report.data(), data + offset, std::min(wire::kReportBytes, size - offset));
    const wire::StreamDecoder::Step step = decoder.Feed(report);
    if (step.payload.size() > wire::kMaxStreamPayload) __builtin_trap();
    if (step.event == wire::StreamDecoder::Event::kData) {
      crc.Update(step.payload);
      bytes += static_cast<std::uint32_t>(step.payload.size());
    } else if (step.event == wire::StreamDecoder::Event::kEnd) {
      wire::StreamTrailer t;
      if (wire::Decode(step.payload, t) != Status::kOk) __builtin_trap();
      if (t.crc32 != crc.value() || t.total_bytes != bytes) __builtin_trap();
    }
  }
  return 0;
}
