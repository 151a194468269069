#include "vibid/device/dfuse.hpp"

#include <gtest/gtest.h>

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
  EXPECT_EQ(s[5].address, 0x08020000u);  // sector 5
  EXPECT_EQ(s[11].address, 0x080E0000u); // sector 11
  EXPECT_EQ(s[11].address + s[11].bytes, 0x08100000u);
}

TEST(ParseDfuSeLayout, RefusesMalformedStrings) {
  for (const char* bad : {"", "Internal/0x0/1*1Kg", "@Flash/zz/1*1Kg", "@Flash/0x0/1x1Kg", "@Flash/0x0/0*1Kg",
                          "@Flash/0x0/1*1Qg", "@Flash/0xFFFFFFFF/2*1Kg"}) {
    EXPECT_THROW(ParseDfuSeLayout(bad), DeviceError) << bad;
  }
}

}  // namespace
}  // namespace vibid::device
