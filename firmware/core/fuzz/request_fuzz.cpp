// Fuzzes the command server's request parsing: the input is cut into 64-byte reports (the last
// one zero-padded) sent to a core on a fake port, with a frame delivered between reports so
// acquisitions, triggers, the DOB and streams run too. The first input byte chooses whether the
// board starts calibrated with the golden record that carries a filter. Every report must be
// answered; nothing may crash.
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "core_harness.hpp"
#include "golden_vectors.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace vibid;
  fw::testing::CoreHarness h;
  (void)h.core.Boot();
  if (size == 0) return 0;
  if ((data[0] & 1u) != 0) {
    static std::array<std::uint8_t, wire::kCalRecordBytes> record{};
    static const std::size_t record_size = wire::testing::GoldenVector("calibration_record_dob", record);
    if (record_size != record.size() || h.Upload(record) != Status::kOk ||
        h.Request(wire::Command::kCalCommit).status() != Status::kOk) {
      __builtin_trap();
    }
  }
  ++data;
  --size;
  std::int32_t k = 0;
  for (std::size_t offset = 0; offset < size; offset += wire::kReportBytes) {
    wire::Report report{};
    std::memcpy(report.data(), data + offset, std::min(wire::kReportBytes, size - offset));
    h.link.ClearOut();
    h.link.Push(report);
    h.Drain();
    // Every request is answered: with a full response report, or by a stream whose first report
    // may already be a stream data report (a log read answers with its data).
    wire::Report answer{};
    if (!h.link.Pop(answer)) __builtin_trap();
    if (!wire::IsStreamData(answer)) {
      wire::Header header;
      if (wire::DecodeHeader(answer, header) != Status::kOk) __builtin_trap();
      if ((header.flags & wire::kFlagResponse) == 0) __builtin_trap();
    }
    h.fake.frames.Emit({k, 2048 - k, 3 * k, -k, k * k, 7});
    ++k;
  }
  return 0;
}
