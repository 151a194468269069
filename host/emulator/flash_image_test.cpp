// The emulated flash: the STM32F405 sector map (RM0090 table 5), NOR programming, persistence.
#include "flash_image.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "emu_port.hpp"
#include "vibid/common/error.hpp"

namespace vibid::emu {
namespace {

std::filesystem::path TempFile(const char* name) {
  return std::filesystem::temp_directory_path() /
         ("vibid_flash_" + std::to_string(::getpid()) + "_" + name);
}

TEST(FlashImage, SectorMapOfTheStm32f405) {
  // RM0090 table 5: sectors 0-3 of 16 KiB, 4 of 64 KiB, 5-11 of 128 KiB from 0x0800 0000.
  EXPECT_EQ(FlashImage::SectorStart(0), 0x08000000u);
  EXPECT_EQ(FlashImage::SectorStart(2), 0x08008000u);
  EXPECT_EQ(FlashImage::SectorStart(4), 0x08010000u);
  EXPECT_EQ(FlashImage::SectorStart(5), 0x08020000u);
  EXPECT_EQ(FlashImage::SectorStart(11), 0x080E0000u);
  EXPECT_EQ(FlashImage::SectorStart(11) + FlashImage::SectorBytes(11), 0x08100000u);
  EXPECT_EQ(FlashImage::SectorOf(0x0800BFFF), 2);
  EXPECT_EQ(FlashImage::SectorOf(0x0801FFFF), 4);
  EXPECT_FALSE(FlashImage::SectorOf(0x08100000).has_value());
  EXPECT_FALSE(FlashImage::Contains(0x080FFFFF, 2));
  EXPECT_TRUE(FlashImage::Contains(0x080FFFFF, 1));
  // The port's calibration slots sit at the starts of their sectors in this map.
  for (int slot = 0; slot < 2; ++slot) {
    EXPECT_EQ(FlashCalibrationSlots::kSlotAddress[slot],
              FlashImage::SectorStart(FlashCalibrationSlots::kSlotSector[slot]));
    EXPECT_EQ(FlashImage::SectorBytes(FlashCalibrationSlots::kSlotSector[slot]), 16u * 1024u);
  }
}

TEST(FlashImage, NorProgrammingOnlyClearsBits) {
  FlashImage f("");
  const std::array<std::uint8_t, 2> first = {0xF0, 0x0F}, second = {0x3C, 0xFF};
  EXPECT_TRUE(f.Program(0x08010000, first));
  EXPECT_FALSE(f.Program(0x08010000, second));  // 0xF0 & 0x3C = 0x30: verify fails
  std::array<std::uint8_t, 2> back{};
  ASSERT_TRUE(f.Read(0x08010000, back));
  EXPECT_EQ(back[0], 0x30);
  EXPECT_EQ(back[1], 0x0F);
  EXPECT_TRUE(f.EraseSector(4));
  ASSERT_TRUE(f.Read(0x08010000, back));
  EXPECT_EQ(back[0], 0xFF);
  EXPECT_FALSE(f.Program(0x07FFFFFF, first));
  EXPECT_FALSE(f.EraseSector(12));
}

TEST(FlashImage, CalibrationSlotsPersistInTheFile) {
  const auto path = TempFile("slots.bin");
  std::filesystem::remove(path);
  {
    FlashImage f(path.string());
    FlashCalibrationSlots slots(f);
    const std::array<std::uint8_t, 3> data = {1, 2, 3};
    ASSERT_EQ(slots.Erase(fw::CalibrationFlash::Slot::kB), Status::kOk);
    ASSERT_EQ(slots.Program(fw::CalibrationFlash::Slot::kB, 100, data), Status::kOk);
    EXPECT_EQ(slots.Program(fw::CalibrationFlash::Slot::kB, 16 * 1024 - 2, data),
              Status::kOutOfRange);
  }
  {
    FlashImage f(path.string());
    std::array<std::uint8_t, 3> back{};
    ASSERT_TRUE(f.Read(0x0800C000 + 100, back));  // slot B = sector 3, as on the board
    EXPECT_EQ(back[2], 3);
    FlashCalibrationSlots slots(f);
    ASSERT_EQ(slots.Read(fw::CalibrationFlash::Slot::kB, 100, back), Status::kOk);
    EXPECT_EQ(back[0], 1);
  }
  EXPECT_EQ(std::filesystem::file_size(path), 1024u * 1024u);
  std::filesystem::resize_file(path, 1000);
  try {
    FlashImage f(path.string());
    FAIL() << "a short flash file was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("is 1000 bytes, not the 1048576"), std::string::npos);
  }
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace vibid::emu
