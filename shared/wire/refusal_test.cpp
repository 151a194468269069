// The refusal payload (protocol 2.1) against the golden reports of scripts/golden/wire_vectors.py,
// and the two directions of compatibility with 2.0: a refusal without a payload (a 2.0 device)
// decodes as kUnspecified, and the header of a refusal with a payload decodes as before (a 2.0
// host reads only the header's status).
#include "vibid/shared/wire/refusal.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstring>

#include "golden_vectors.hpp"
#include "vibid/shared/wire/commands.hpp"
#include "vibid/shared/wire/stream.hpp"

namespace vibid::wire {
namespace {

using testing::GoldenReport;

TEST(Refusal, EncodesAsGolden) {
  // Golden: acq-configure refused invalid-argument, reason observer-rate (11), detail 5000 Hz.
  const Refusal r{.reason = Reason::kObserverRate, .detail = 5000};
  Report out{};
  ASSERT_EQ(BuildReport(Command::kAcqConfigure, 0x0A0D, 0, kFlagResponse, Status::kInvalidArgument,
                        r, out),
            Status::kOk);
  EXPECT_EQ(out, GoldenReport("refusal_reason_response"));

  const Refusal staged{.reason = Reason::kNothingStaged};
  ASSERT_EQ(BuildReport(Command::kCalCommit, 0x0C0F, 0, kFlagResponse, Status::kFailedPrecondition,
                        staged, out),
            Status::kOk);
  EXPECT_EQ(out, GoldenReport("refusal_nothing_staged"));

  // self-test of check 17, which the board does not have (wire_vectors.py).
  const Refusal check{.reason = Reason::kUnknownCheck, .detail = 18};
  ASSERT_EQ(BuildReport(Command::kSelfTest, 0x0108, 0, kFlagResponse, Status::kInvalidArgument,
                        check, out),
            Status::kOk);
  EXPECT_EQ(out, GoldenReport("refusal_unknown_check"));
  EXPECT_STREQ(ReasonName(Reason::kUnknownCheck), "unknown-check");
  EXPECT_STREQ(ReasonName(Reason::kInternalClock), "internal-clock");
}

TEST(Refusal, DecodesGolden) {
  const Report golden = GoldenReport("refusal_reason_response");
  Header h;
  ASSERT_EQ(DecodeHeader(golden, h), Status::kOk);
  EXPECT_EQ(h.status, Status::kInvalidArgument);
  EXPECT_EQ(h.payload_length, Refusal::kBytes);
  Refusal r;
  ASSERT_EQ(Decode(PayloadOf(golden), r), Status::kOk);
  EXPECT_EQ(r.reason, Reason::kObserverRate);
  EXPECT_EQ(r.detail, 5000u);
  EXPECT_STREQ(ReasonName(r.reason), "observer-rate");
}

TEST(Refusal, AnEmptyPayloadIsA20DeviceWithoutReason) {
  const Report golden = GoldenReport("refusal_response");  // 2.0: no payload
  Refusal r{.reason = Reason::kTrigger, .detail = 9};
  ASSERT_EQ(Decode(PayloadOf(golden), r), Status::kOk);
  EXPECT_EQ(r.reason, Reason::kUnspecified);
  EXPECT_EQ(r.detail, 0u);
}

TEST(Refusal, ReadsTheFirstEightBytesAndRefusesFewer) {
  std::array<std::uint8_t, 12> longer{24, 0, 0, 0, 3, 0, 0, 0, 0xAA, 0xBB, 0xCC, 0xDD};
  Refusal r;
  ASSERT_EQ(Decode(longer, r), Status::kOk);  // a later minor may append fields
  EXPECT_EQ(r.reason, Reason::kScenarioParameter);
  EXPECT_EQ(r.detail, 3u);
  for (std::size_t n = 1; n < Refusal::kBytes; ++n) {
    EXPECT_EQ(Decode(std::span<const std::uint8_t>(longer).first(n), r), Status::kInvalidArgument)
        << n;
  }
}

TEST(Refusal, AnUnknownReasonDecodesAndSaysSo) {
  // A newer device's reason: the host still gets status and detail.
  const std::array<std::uint8_t, 8> bytes{0x34, 0x12, 0, 0, 7, 0, 0, 0};
  Refusal r;
  ASSERT_EQ(Decode(bytes, r), Status::kOk);
  EXPECT_EQ(static_cast<std::uint16_t>(r.reason), 0x1234);
  EXPECT_STREQ(ReasonName(r.reason), "unknown");
}

TEST(Refusal, EveryReasonHasItsOwnName) {
  // Append only: the numbers are the wire values, pinned here as in protocol.md.
  EXPECT_EQ(static_cast<int>(Reason::kObserverRate), 11);
  EXPECT_EQ(static_cast<int>(Reason::kNothingStaged), 13);
  EXPECT_EQ(static_cast<int>(Reason::kUnknownScenario), 23);
  for (int i = 0; i <= static_cast<int>(kLastReason); ++i) {
    const char* a = ReasonName(static_cast<Reason>(i));
    EXPECT_STRNE(a, "unknown") << i;
    for (int k = 0; k < i; ++k) EXPECT_STRNE(a, ReasonName(static_cast<Reason>(k))) << i;
  }
  EXPECT_STREQ(ReasonName(static_cast<Reason>(static_cast<int>(kLastReason) + 1)), "unknown");
}

TEST(Refusal, AStreamRefusalHandsOverItsReason) {
  Report refusal{};
  const Refusal sent{.reason = Reason::kLogOverwritten, .detail = 190171};
  ASSERT_EQ(
      BuildReport(Command::kLogRead, 0x7777, 0, kFlagResponse, Status::kOutOfRange, sent, refusal),
      Status::kOk);
  StreamDecoder d(Command::kLogRead, 0x7777);
  ASSERT_EQ(d.Feed(GoldenReport("log_stream_0")).event, StreamDecoder::Event::kData);
  const auto step = d.Feed(refusal);
  ASSERT_EQ(step.event, StreamDecoder::Event::kRefused);
  EXPECT_EQ(step.status, Status::kOutOfRange);
  Refusal got;
  ASSERT_EQ(Decode(step.payload, got), Status::kOk);
  EXPECT_EQ(got.reason, Reason::kLogOverwritten);
  EXPECT_EQ(got.detail, 190171u);
}

}  // namespace
}  // namespace vibid::wire
