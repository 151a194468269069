// The host's sentence for each refusal: the board's reason (golden payload of
// scripts/golden/wire_vectors.py) turned into the cause and the way out; a 2.0 board's refusal,
// which names no reason, reads as it always did.
#include "vibid/device/refusal_text.hpp"

#include <gtest/gtest.h>

#include <array>

#include "vibid/shared/wire/commands.hpp"

namespace vibid::device {
namespace {

std::array<std::uint8_t, wire::Refusal::kBytes> Payload(wire::Reason reason,
                                                        std::uint32_t detail = 0) {
  std::array<std::uint8_t, wire::Refusal::kBytes> b{};
  wire::Encode(wire::Refusal{.reason = reason, .detail = detail}, b);
  return b;
}

TEST(RefusalText, ObserverRateNamesTheRateAndTheWaysOut) {
  // The golden refusal_reason_response payload: 0b 00 00 00 88 13 00 00 (observer-rate, 5000).
  const std::array<std::uint8_t, 8> golden{0x0b, 0, 0, 0, 0x88, 0x13, 0, 0};
  EXPECT_EQ(RefusalMessage(static_cast<std::uint8_t>(wire::Command::kAcqConfigure),
                           Status::kInvalidArgument, golden),
            "the device refused acq-configure: the board's observer was designed for 5000 Hz and "
            "runs at that rate only; acquire at --rate-hz 5000, or without the observer "
            "(--no-dob), or design and upload an observer for this rate (vibid dob design "
            "--fs-hz) [invalid-argument, observer-rate]");
}

TEST(RefusalText, A20BoardReadsAsBefore) {
  EXPECT_EQ(RefusalMessage(static_cast<std::uint8_t>(wire::Command::kDobControl),
                           Status::kFailedPrecondition, {}),
            "the device refused dob-control: failed-precondition (not allowed in the device's "
            "current state)");
  EXPECT_EQ(RefusalMessage(static_cast<std::uint8_t>(wire::Command::kAcqConfigure),
                           Status::kInvalidArgument, {}),
            "the device refused acq-configure: invalid-argument");
}

TEST(RefusalText, EveryReasonSaysItsCauseAndAWayOut) {
  for (int i = 1; i <= static_cast<int>(wire::kLastReason); ++i) {
    const auto reason = static_cast<wire::Reason>(i);
    const std::string m = RefusalMessage(static_cast<std::uint8_t>(wire::Command::kPing),
                                         Status::kInvalidArgument, Payload(reason, 7));
    if (reason == wire::Reason::kPortRefused) continue;  // the port's own cause
    EXPECT_NE(m.find("; "), std::string::npos) << "cause; way out: " << m;
    EXPECT_NE(m.find(std::string(wire::ReasonName(reason)) + "]"), std::string::npos) << m;
  }
  EXPECT_NE(RefusalMessage(0x12, Status::kFailedPrecondition, Payload(wire::Reason::kNothingStaged))
                .find("no calibration record is staged; stage one first (vibid cal upload"),
            std::string::npos);
  EXPECT_NE(
      RefusalMessage(0x24, Status::kOutOfRange, Payload(wire::Reason::kLogOverwritten, 190171))
          .find("the oldest the board holds is record 190171 (vibid log pull --from 190171)"),
      std::string::npos);
  EXPECT_NE(
      RefusalMessage(0x20, Status::kInvalidArgument, Payload(wire::Reason::kSamplePeriod, 100))
          .find("outside the board's 1 Hz .. 10000 Hz; choose --rate-hz from 1 to 10000"),
      std::string::npos);
}

TEST(RefusalText, AReasonThisHostDoesNotKnowIsSaidAsSuch) {
  const std::array<std::uint8_t, 8> newer{0x34, 0x12, 0, 0, 0, 0, 0, 0};
  EXPECT_EQ(RefusalMessage(0x20, Status::kInvalidArgument, newer),
            "the device refused acq-configure: invalid-argument (reason 4660, which this host does "
            "not know; use a host that matches the firmware) [invalid-argument, unknown]");
}

}  // namespace
}  // namespace vibid::device
