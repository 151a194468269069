// The image CRC check against its trailer, on a flat image built as the linker lays one out:
// head, calibration sectors (not the image's), body, trailer.
#include "image_crc.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <string_view>
#include <vector>

#include "port_test_fixture.hpp"
#include "regs/peripherals.hpp"

namespace vibid::fw::stm32::test {
namespace {

constexpr std::uint32_t kBase = 0x08000000;

void PutU32(std::vector<std::uint8_t>& v, std::uint32_t x) {
  for (int i = 0; i < 4; ++i) v.push_back(static_cast<std::uint8_t>(x >> (8 * i)));
}

// head "vibid-hd" at 0x08000000, 8 bytes standing for the calibration sectors, body
// "123456789" and 3 zero bytes at 0x08000010, the trailer at 0x0800001C (its CRC word at
// 0x08000030). The stored CRC is zlib's over the head then the body up to the CRC word:
//   python3 -c "import struct,zlib; A=0x08000000; h=b'vibid-hd';
//     b=b'123456789\0\0\0'+struct.pack('<5I',0x43524376,A,A+8,A+16,A+48);
//     print(hex(zlib.crc32(b,zlib.crc32(h))))"  -> 0xa11e7337
constexpr std::uint32_t kZlibCrc = 0xA11E7337;

std::vector<std::uint8_t> FlatImage(std::uint32_t crc = kZlibCrc) {
  std::vector<std::uint8_t> v;
  for (const char c : std::string_view("vibid-hd")) v.push_back(static_cast<std::uint8_t>(c));
  v.insert(v.end(), 8, 0x5A);
  for (const char c : std::string_view("123456789")) v.push_back(static_cast<std::uint8_t>(c));
  v.insert(v.end(), 3, 0);
  PutU32(v, kImageCrcMagic);
  PutU32(v, kBase);
  PutU32(v, kBase + 8);
  PutU32(v, kBase + 16);
  PutU32(v, kBase + 48);
  PutU32(v, crc);
  return v;
}

ImageCrcResult Check(const std::vector<std::uint8_t>& v) {
  return CheckImageCrc({.bytes = v.data(), .address = kBase, .size = v.size()});
}

class ImageCrcTest : public PortTest {};

TEST_F(ImageCrcTest, TheBuildsCrcMatchesAndTheCalibrationSectorsAreLeftOut) {
  std::vector<std::uint8_t> image = FlatImage();
  ASSERT_EQ(image.size(), 52u);
  ImageCrcResult r = Check(image);
  ASSERT_TRUE(r.trailer_valid);
  EXPECT_EQ(r.computed, kZlibCrc);
  EXPECT_EQ(r.stored, kZlibCrc);
  EXPECT_GE(regs().CountWrites(iwdg::kKr), 2u);  // fed after each range
  // Calibration written between head and body changes nothing.
  image[10] = 0x00;
  EXPECT_EQ(Check(image).computed, kZlibCrc);
}

TEST_F(ImageCrcTest, AFlippedImageByteOrCrcWordIsAMismatch) {
  for (const std::size_t at : {std::size_t{0}, std::size_t{7}, std::size_t{16}, std::size_t{27}}) {
    std::vector<std::uint8_t> image = FlatImage();
    image[at] ^= 0x01;
    const ImageCrcResult r = Check(image);
    ASSERT_TRUE(r.trailer_valid) << at;
    EXPECT_NE(r.computed, r.stored) << "byte " << at;
  }
  const ImageCrcResult r = Check(FlatImage(0xFFFFFFFF));  // the linker's placeholder
  ASSERT_TRUE(r.trailer_valid);
  EXPECT_EQ(r.computed, kZlibCrc);
  EXPECT_NE(r.computed, r.stored);
}

TEST_F(ImageCrcTest, ATrailerThatDoesNotParseIsNotValid) {
  std::vector<std::uint8_t> bad_magic = FlatImage();
  bad_magic[28] ^= 0x01;
  EXPECT_FALSE(Check(bad_magic).trailer_valid);
  // The CRC word must be the image's last word: one byte more after the trailer breaks it.
  std::vector<std::uint8_t> longer = FlatImage();
  longer.push_back(0);
  EXPECT_FALSE(Check(longer).trailer_valid);
  // Ranges out of order (head end past body start).
  std::vector<std::uint8_t> crossed = FlatImage();
  crossed[36] = 0x20;  // head_end = 0x08000020 > body_start 0x08000010
  EXPECT_FALSE(Check(crossed).trailer_valid);
  // A head below the view would be read from outside it.
  std::vector<std::uint8_t> image = FlatImage();
  EXPECT_FALSE(
      CheckImageCrc({.bytes = image.data() + 4, .address = kBase + 4, .size = image.size() - 4})
          .trailer_valid);
  EXPECT_FALSE(CheckImageCrc({.bytes = image.data(), .address = kBase, .size = 20}).trailer_valid);
}

}  // namespace
}  // namespace vibid::fw::stm32::test
