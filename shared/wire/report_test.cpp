#include "vibid/shared/wire/report.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>

#include "golden_vectors.hpp"
#include "vibid/shared/wire/commands.hpp"

namespace vibid::wire {
namespace {

Report Golden(const char* name) { return testing::GoldenReport(name); }

// A change of the protocol version must be mirrored in the golden file (and so in the script).
TEST(Report, ProtocolVersionMatchesGoldenFile) {
  EXPECT_EQ(testing::GoldenConstant("protocol_major"), kProtocolMajor);
  EXPECT_EQ(testing::GoldenConstant("protocol_minor"), kProtocolMinor);
}

TEST(Report, EncodesPingRequestLikeGolden) {
  const std::array<std::uint8_t, 5> hello{'h', 'e', 'l', 'l', 'o'};
  Report out{};
  ASSERT_EQ(BuildReport(Command::kPing, 0x1234, 0, 0, Status::kOk, hello, out), Status::kOk);
  EXPECT_TRUE(out == Golden("ping_request"));
}

// Hand-decoded: 56 42 | 02 | 01 | 00 | 00 | 34 12 | 00 00 | 05 | 00 | "hello" | zeros.
TEST(Report, DecodesPingRequestByHand) {
  const Report r = Golden("ping_request");
  EXPECT_EQ(r[0], 0x56);
  EXPECT_EQ(r[1], 0x42);
  Header h;
  ASSERT_EQ(DecodeHeader(r, h), Status::kOk);
  EXPECT_EQ(h.protocol_major, 2);
  EXPECT_EQ(h.command, 0x01);
  EXPECT_EQ(h.status, Status::kOk);
  EXPECT_EQ(h.flags, 0);
  EXPECT_EQ(h.token, 0x1234);
  EXPECT_EQ(h.sequence, 0);
  EXPECT_EQ(h.payload_length, 5);
  const auto payload = PayloadOf(r);
  ASSERT_EQ(payload.size(), 5u);
  EXPECT_EQ(payload[0], 'h');
  EXPECT_EQ(payload[4], 'o');
}

TEST(Report, DecodesRefusalResponse) {
  Header h;
  ASSERT_EQ(DecodeHeader(Golden("refusal_response"), h), Status::kOk);
  EXPECT_EQ(h.command, 0x20);
  EXPECT_EQ(h.status, Status::kFailedPrecondition);
  EXPECT_EQ(h.flags, kFlagResponse);
  EXPECT_EQ(h.token, 0x0A0C);
  EXPECT_EQ(h.payload_length, 0);
}

TEST(Report, RefusesMalformedHeaders) {
  Header h;
  Report r = Golden("ping_request");
  r[0] = 0x57;
  EXPECT_EQ(DecodeHeader(r, h), Status::kDataLoss);

  r = Golden("ping_request");
  r[kOffProtocolMajor] = kProtocolMajor + 1;
  EXPECT_EQ(DecodeHeader(r, h), Status::kVersionMismatch);
  EXPECT_EQ(h.protocol_major, kProtocolMajor + 1);

  r = Golden("ping_request");
  r[kOffPayloadLength] = kMaxPayload + 1;
  EXPECT_EQ(DecodeHeader(r, h), Status::kInvalidArgument);
  EXPECT_EQ(PayloadOf(r).size(), kMaxPayload);

  r = Golden("ping_request");
  r[kOffFlags] = 0x80;
  EXPECT_EQ(DecodeHeader(r, h), Status::kInvalidArgument);

  r = Golden("ping_request");
  r[kOffReserved] = 1;
  EXPECT_EQ(DecodeHeader(r, h), Status::kInvalidArgument);

  r = Golden("ping_request");
  r[kOffStatus] = 200;
  EXPECT_EQ(DecodeHeader(r, h), Status::kInvalidArgument);
}

TEST(Report, RefusesOversizePayload) {
  std::array<std::uint8_t, kMaxPayload + 1> big{};
  big.fill(0xAB);
  Report out{};
  out.fill(0x11);
  EXPECT_EQ(EncodeReport(Header{}, big, out), Status::kOutOfRange);
  EXPECT_TRUE(std::all_of(out.begin(), out.end(), [](std::uint8_t b) { return b == 0; }));
}

}  // namespace
}  // namespace vibid::wire
