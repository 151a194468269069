// The USART frame codec: layout against bytes computed independently (Python's zlib.crc32),
// and the decoder's recovery from noise, truncation and corruption.
#include "vibid/shared/wire/serial_frame.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <span>

namespace vibid::wire {
namespace {

Report Counting() {
  Report r{};
  for (std::size_t i = 0; i < r.size(); ++i) r[i] = static_cast<std::uint8_t>(i);
  return r;
}

// Feeds bytes; returns how many frames completed, the last one in `last`.
int Feed(SerialFrameDecoder& d, std::span<const std::uint8_t> bytes, Report& last) {
  int frames = 0;
  Report r{};
  for (std::uint8_t b : bytes) {
    if (d.Push(b, r)) {
      ++frames;
      last = r;
    }
  }
  return frames;
}

TEST(SerialFrame, LayoutMatchesIndependentCrc) {
  const SerialFrameBytes f = EncodeSerialFrame(Counting());
  EXPECT_EQ(f[0], 0x56);
  EXPECT_EQ(f[1], 0x46);
  EXPECT_EQ(f[2], 64);
  EXPECT_EQ(f[3], 0);
  EXPECT_EQ(f[66], 63);
  // Reference: python3 -c "import zlib; print(hex(zlib.crc32(bytes([64]) + bytes(range(64)))))"
  // -> 0x2d5f5038, stored little-endian.
  EXPECT_EQ(f[67], 0x38);
  EXPECT_EQ(f[68], 0x50);
  EXPECT_EQ(f[69], 0x5f);
  EXPECT_EQ(f[70], 0x2d);
}

TEST(SerialFrame, RoundTripBackToBack) {
  SerialFrameDecoder d;
  Report a = Counting();
  Report b{};
  b.fill(0x56);  // Payload full of sync bytes must not confuse the decoder.
  const SerialFrameBytes fa = EncodeSerialFrame(a);
  const SerialFrameBytes fb = EncodeSerialFrame(b);
  Report got{};
  const int n1 = Feed(d, fa, got);
  EXPECT_EQ(n1, 1);
  EXPECT_EQ(got, a);
  const int n2 = Feed(d, fb, got);
  EXPECT_EQ(n2, 1);
  EXPECT_EQ(got, b);
  EXPECT_EQ(d.counters().frames, 2U);
  EXPECT_EQ(d.counters().skipped_bytes, 0U);
}

TEST(SerialFrame, NoiseBeforeFrameIsSkipped) {
  SerialFrameDecoder d;
  const std::array<std::uint8_t, 5> noise = {0x00, 0x56, 0x13, 0x56, 0x56};
  Report got{};
  const int n3 = Feed(d, noise, got);
  EXPECT_EQ(n3, 0);
  const int n4 = Feed(d, EncodeSerialFrame(Counting()), got);
  EXPECT_EQ(n4, 1);
  EXPECT_EQ(got, Counting());
  EXPECT_EQ(d.counters().skipped_bytes, 5U);
}

TEST(SerialFrame, CorruptFrameIsRejectedAndNextOneDecodes) {
  SerialFrameDecoder d;
  SerialFrameBytes bad = EncodeSerialFrame(Counting());
  bad[40] ^= 0x01;
  Report got{};
  const int n5 = Feed(d, bad, got);
  EXPECT_EQ(n5, 0);
  EXPECT_EQ(d.counters().crc_errors, 1U);
  Report other{};
  other.fill(0xA5);
  const int n6 = Feed(d, EncodeSerialFrame(other), got);
  EXPECT_EQ(n6, 1);
  EXPECT_EQ(got, other);
}

TEST(SerialFrame, TruncatedFrameThenGoodFrame) {
  // A frame cut short (sender restarted) followed by a whole frame: the good frame is found
  // inside the bytes the decoder already buffered.
  SerialFrameDecoder d;
  const SerialFrameBytes first = EncodeSerialFrame(Counting());
  Report other{};
  other.fill(0x11);
  const SerialFrameBytes second = EncodeSerialFrame(other);
  Report got{};
  const int n7 = Feed(d, std::span<const std::uint8_t>(first).first(30), got);
  EXPECT_EQ(n7, 0);
  const int n8 = Feed(d, second, got);
  EXPECT_EQ(n8, 1);
  EXPECT_EQ(got, other);
}

TEST(SerialFrame, WrongLengthByteIsNotAFrame) {
  SerialFrameDecoder d;
  SerialFrameBytes f = EncodeSerialFrame(Counting());
  f[2] = 63;
  Report got{};
  const int n9 = Feed(d, f, got);
  EXPECT_EQ(n9, 0);
  EXPECT_EQ(d.counters().frames, 0U);
}

TEST(SerialFrame, EveryFrameSurvivesNoiseBetweenFrames) {
  // 200 frames, each preceded by 0..40 noise bytes biased towards the sync bytes and the length
  // byte (the worst case: false frame starts that swallow part of a real frame). Every real frame
  // must come out, in order, with nothing extra.
  std::uint32_t lcg = 12345;
  auto next = [&lcg]() {
    lcg = lcg * 1664525U + 1013904223U;  // Numerical Recipes LCG
    return lcg >> 24;
  };
  SerialFrameDecoder d;
  Report got{};
  int delivered = 0;
  bool in_order = true;
  for (int k = 0; k < 200; ++k) {
    const std::uint32_t noise = next() % 41;
    for (std::uint32_t i = 0; i < noise; ++i) {
      const std::uint32_t pick = next() % 4;
      const std::uint8_t b = pick == 0   ? kSerialSync0
                             : pick == 1 ? kSerialSync1
                             : pick == 2 ? 64
                                         : static_cast<std::uint8_t>(next());
      if (d.Push(b, got)) in_order = false;  // Noise never forms a frame with a valid CRC here.
    }
    Report report{};
    for (std::size_t i = 0; i < report.size(); ++i) report[i] = static_cast<std::uint8_t>(next());
    report[0] = static_cast<std::uint8_t>(k);
    int frames = 0;
    for (std::uint8_t b : EncodeSerialFrame(report)) {
      if (d.Push(b, got)) {
        ++frames;
        if (got != report) in_order = false;
      }
    }
    delivered += frames;
  }
  EXPECT_EQ(delivered, 200);
  EXPECT_TRUE(in_order);
}

}  // namespace
}  // namespace vibid::wire
