#include "vibid/device/dfuse.hpp"

#include <gtest/gtest.h>

#include "vibid/common/error.hpp"
#include "vibid/common/testing/input_error.hpp"
#include "vibid/device/error.hpp"

namespace vibid::device {
namespace {

TEST(ParseDfuSeLayout, Stm32f405InternalFlash) {
  // The STM32F405 ROM bootloader's string (ST AN2606; RM0090 table 5: 4 x 16 KiB, 1 x 64 KiB,
  // 7 x 128 KiB sectors from 0x08000000, 1 MiB in all).
  const auto s = ParseDfuSeLayout("@Internal Flash  /0x08000000/04*016Kg,01*064Kg,07*128Kg");
  ASSERT_EQ(s.size(), 12u);
  EXPECT_EQ(s[0].address, 0x08000000u);
  EXPECT_EQ(s[0].bytes, 16u * 1024);
  EXPECT_EQ(s[4].address, 0x08010000u);  // RM0090: sector 4
  EXPECT_EQ(s[4].bytes, 64u * 1024);
  EXPECT_EQ(s[5].address, 0x08020000u);   // sector 5
  EXPECT_EQ(s[11].address, 0x080E0000u);  // sector 11
  EXPECT_EQ(s[11].address + s[11].bytes, 0x08100000u);
}

TEST(ParseDfuSeLayout, RefusesMalformedStrings) {
  for (const char* bad : {"", "Internal/0x0/1*1Kg", "@Flash/zz/1*1Kg", "@Flash/0x0/1x1Kg",
                          "@Flash/0x0/0*1Kg", "@Flash/0x0/1*1Qg", "@Flash/0xFFFFFFFF/2*1Kg"}) {
    EXPECT_THROW(ParseDfuSeLayout(bad), DeviceError) << bad;
  }
}

std::string MessageOf(const std::vector<std::uint8_t>& image, std::uint32_t address) {
  return InputErrorOf(
      [&] {
        PlanFlash(ParseDfuSeLayout(dfu::kStm32f405FlashLayout), image, address,
                  std::span(&kCalibrationSectors, 1));
      },
      "accepted");
}

// A board image as objcopy --gap-fill 0xff makes it: vectors and startup in sectors 0-1, the
// calibration sectors 2-3 as gap, the rest from sector 4 (the board's linker script).
TEST(PlanFlash, SkipsTheCalibrationSectorsOfAWholeBoardImage) {
  std::vector<std::uint8_t> image(0x10000 + 300000, 0x5A);
  std::fill(image.begin() + 0x8000, image.begin() + 0x10000, 0xFF);
  const FlashPlan p = PlanFlash(ParseDfuSeLayout(dfu::kStm32f405FlashLayout), image, 0x08000000,
                                std::span(&kCalibrationSectors, 1));
  // RM0090 table 5: sectors 0, 1 (16 KiB), 4 (64 KiB at 0x08010000), 5 and 6 (128 KiB); the image
  // ends at 0x08010000 + 300000 = 0x0805B3E0, inside sector 6 (0x08040000-0x0805FFFF).
  EXPECT_EQ(p.erase, (std::vector<std::uint32_t>{0x08000000, 0x08004000, 0x08010000, 0x08020000,
                                                 0x08040000}));
  ASSERT_EQ(p.write.size(), 2u);
  EXPECT_EQ(p.write[0].address, 0x08000000u);
  EXPECT_EQ(p.write[0].bytes, 0x8000u);
  EXPECT_EQ(p.write[1].address, 0x08010000u);
  EXPECT_EQ(p.write[1].bytes, 300000u);
}

TEST(PlanFlash, ApplicationFromSector4UpToTheEndOfTheFlash) {
  const std::vector<std::uint8_t> image(0x100000 - 0x10000, 0x00);
  const FlashPlan p = PlanFlash(ParseDfuSeLayout(dfu::kStm32f405FlashLayout), image, 0x08010000,
                                std::span(&kCalibrationSectors, 1));
  EXPECT_EQ(p.erase.size(), 8u);  // sectors 4..11
  ASSERT_EQ(p.write.size(), 1u);
  EXPECT_EQ(p.write[0].bytes, image.size());
  EXPECT_NE(MessageOf(std::vector<std::uint8_t>(image.size() + 1), 0x08010000)
                .find("does not fit the flash"),
            std::string::npos);
}

TEST(PlanFlash, RefusesEmptyOversizeAndCalibrationData) {
  EXPECT_EQ(MessageOf({}, 0x08000000), "the image is empty");
  EXPECT_EQ(MessageOf(std::vector<std::uint8_t>(0x100001, 0xFF), 0x08000000),
            "the image (1048577 bytes at 0x08000000) does not fit the flash (1048576 bytes at "
            "0x08000000)");
  std::vector<std::uint8_t> image(0x20000, 0xFF);
  image[0x8010] = 0;  // in sector 2
  EXPECT_NE(MessageOf(image, 0x08000000).find("data at 0x08008010"), std::string::npos)
      << MessageOf(image, 0x08000000);
  EXPECT_EQ(
      MessageOf(std::vector<std::uint8_t>(16, 0), 0x07FFFFF0),
      "the image (16 bytes at 0x07fffff0) does not fit the flash (1048576 bytes at 0x08000000)");
}

}  // namespace
}  // namespace vibid::device
