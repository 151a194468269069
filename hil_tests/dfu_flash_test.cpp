// DFU flash against the spawned emulator: enter-DFU, the DfuSe bootloader personality over USB/IP,
// erase, download, verify, leave; then the emulator's flash file is read back byte for byte.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <thread>

#include "emulator_test.hpp"
#include "run_cli.hpp"
#include "state_wait.hpp"
#include "test_records.hpp"
#include "vibid/device/error.hpp"
#include "vibid/device/flash_board.hpp"
#include "vibid/device/usbip_transport.hpp"

namespace vibid::hil {
namespace {

// The board's flash map (firmware/ports/stm32f405/stm32f405.ld, RM0090 §3.3), as offsets into
// the emulator's 1 MiB flash file: code in sectors 0-1, calibration in sectors 2-3, code again
// from sector 4.
constexpr std::size_t kFlashBytes = 1024 * 1024;
constexpr std::size_t kCalBegin = 0x8000, kCalEnd = 0x10000;
constexpr std::size_t kSector6End = 0x60000;
constexpr std::uint32_t kFlashBase = 0x08000000;

std::vector<std::uint8_t> ReadAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void WriteAll(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()),
             static_cast<std::streamsize>(bytes.size()));
}

/// A whole board image as `objcopy -O binary --gap-fill 0xff` gives it for the board's linker
/// script: 32 KiB of vectors and startup code, the calibration sectors as 0xFF gap, then
/// `application` bytes from 0x08010000. Random bytes from a fixed seed stand in for code.
std::vector<std::uint8_t> BoardImage(std::uint32_t seed, std::size_t application) {
  std::mt19937 rng(seed);
  std::vector<std::uint8_t> image(kCalEnd + application);
  for (auto& b : image) b = static_cast<std::uint8_t>(rng() >> 24);
  std::fill(image.begin() + kCalBegin, image.begin() + kCalEnd, 0xFF);
  return image;
}

/// Waits until the application answers again after the bootloader left.
std::unique_ptr<device::Connection> AwaitApplication(Target& target) {
  const auto deadline = std::chrono::steady_clock::now() + hil::kStateWait;
  for (;;) {
    try {
      return target.Connect();
    } catch (const device::DeviceError& e) {
      if (std::chrono::steady_clock::now() > deadline) {
        throw device::DeviceError("waited " + std::to_string(hil::kStateWait.count()) +
                                  " s for the application after the bootloader: " + e.what());
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
}

class DfuFlashTest : public EmulatorTest {
 protected:
  DfuFlashTest() : EmulatorTest("has no flash file the test can read (emulator only)") {}

  void SetUpEmulator() override {
    dir = vibid::testing::MakeTempDir("flash");
    // A committed calibration, so the calibration sectors hold something to keep.
    auto c = target->Connect();
    const auto record = fw::testing::Encoded(fw::testing::TestRecord(17));
    c->CalPut(std::vector<std::uint8_t>(record.begin(), record.end()));
    c->CalCommit();
    cal_crc = c->GetInfo().cal_crc;
    before = ReadAll(emu->flash_path());
    ASSERT_EQ(before.size(), kFlashBytes);
    ASSERT_TRUE(std::any_of(before.begin() + kCalBegin, before.begin() + kCalEnd,
                            [](std::uint8_t b) { return b != 0xFF; }));
  }
  void TearDown() override {
    std::error_code ec;
    if (!dir.empty()) std::filesystem::remove_all(dir, ec);
  }

  /// The flash file holds `image` from offset 0 outside the calibration sectors, those are as
  /// before, the rest of the last erased sector is erased, and nothing beyond it changed.
  void ExpectFlashHolds(const std::vector<std::uint8_t>& image) {
    const std::vector<std::uint8_t> now = ReadAll(emu->flash_path());
    ASSERT_EQ(now.size(), kFlashBytes);
    EXPECT_TRUE(std::equal(image.begin(), image.begin() + kCalBegin, now.begin())) << "sectors 0-1";
    EXPECT_TRUE(
        std::equal(before.begin() + kCalBegin, before.begin() + kCalEnd, now.begin() + kCalBegin))
        << "the calibration sectors changed";
    const auto differs = std::mismatch(image.begin() + kCalEnd, image.end(), now.begin() + kCalEnd);
    EXPECT_EQ(differs.first, image.end())
        << "first difference at flash offset 0x" << std::hex << (differs.first - image.begin());
    EXPECT_TRUE(std::all_of(now.begin() + static_cast<std::ptrdiff_t>(image.size()),
                            now.begin() + kSector6End, [](std::uint8_t b) { return b == 0xFF; }))
        << "the rest of sector 6 is erased";
    EXPECT_TRUE(std::equal(before.begin() + kSector6End, before.end(), now.begin() + kSector6End))
        << "sectors 7-11";
  }

  /// The application runs again, still calibrated with the same record.
  void ExpectApplicationBackCalibrated() {
    auto c = AwaitApplication(*target);
    EXPECT_EQ(c->info().cal_state, wire::CalState::kCalibrated);
    EXPECT_EQ(c->info().cal_crc, cal_crc);
  }

  std::string dir;
  std::uint32_t cal_crc = 0;
  std::vector<std::uint8_t> before;
};

TEST_F(DfuFlashTest, HostLayerWritesTheImageByteForByteAndKeepsTheCalibration) {
  // 64 KiB head and gap plus 300000 bytes from sector 4: a realistic size, ending mid-block and
  // mid-sector (sector 6).
  const std::vector<std::uint8_t> image = BoardImage(20261121, 300000);
  std::uint64_t blocks = 0;
  const auto started = std::chrono::steady_clock::now();
  const device::FlashBoardResult r =
      device::FlashBoard(device::ParseDeviceSpec(emu->device_spec()), image, kFlashBase,
                         [&](const std::string& phase, std::uint64_t done, std::uint64_t) {
                           if (phase == "download") blocks = done;
                         });
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  std::printf("flashed %zu bytes through the DfuSe bootloader in %.3f s\n", image.size(), seconds);
  EXPECT_TRUE(r.from_application);
  // 32 KiB + 300000 bytes in 2048-byte blocks: 16 + ceil(300000 / 2048) = 16 + 147.
  EXPECT_EQ(blocks, 16u + 147u);
  ASSERT_EQ(r.plan.write.size(), 2u);
  EXPECT_TRUE(emu->AwaitLog("DfuSe bootloader running", 1, std::chrono::milliseconds(0)));
  ExpectApplicationBackCalibrated();
  ExpectFlashHolds(image);
}

TEST_F(DfuFlashTest, CliFlashExitsZeroAndTheBoardRunsItsApplicationAfter) {
  const std::vector<std::uint8_t> image = BoardImage(7, 200000);
  const std::string path = dir + "/firmware.bin";
  WriteAll(path, image);
  const auto r = vibid::testing::RunVibid({"--device", emu->device_spec(), "flash", path});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("flashed 265536 bytes at 0x08000000 in ", 0), 0u) << r.out;
  EXPECT_NE(r.out.find("calibration kept), verified"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("board entered its bootloader"), std::string::npos) << r.err;
  ExpectFlashHolds(image);
  const auto info = vibid::testing::RunVibid({"--device", emu->device_spec(), "info"});
  EXPECT_EQ(info.exit_code, 0) << info.err;
  EXPECT_NE(info.out.find("board         emulator"), std::string::npos) << info.out;
  EXPECT_EQ(info.out.find("calibration   none"), std::string::npos) << info.out;
}

TEST_F(DfuFlashTest, BadImagesAreRefusedBeforeTheBoardLeavesItsApplication) {
  std::vector<std::uint8_t> in_calibration = BoardImage(3, 1000);
  in_calibration[kCalBegin + 0x123] = 0x00;
  const struct {
    const char* name;
    std::vector<std::uint8_t> bytes;
    const char* message;
  } cases[] = {
      {"empty.bin", {}, "empty.bin: the image is empty"},
      {"huge.bin", std::vector<std::uint8_t>(kFlashBytes + 1, 0xFF),
       "huge.bin: the image (1048577 bytes at 0x08000000) does not fit the flash (1048576 bytes at "
       "0x08000000)"},
      {"cal.bin", in_calibration,
       "cal.bin: the image has data at 0x08008123, in the sector at 0x08008000 that holds the "
       "calibration"},
  };
  for (const auto& c : cases) {
    const std::string path = dir + "/" + c.name;
    WriteAll(path, c.bytes);
    const auto r = vibid::testing::RunVibid({"--device", emu->device_spec(), "flash", path});
    EXPECT_EQ(r.exit_code, 1) << c.name << ": " << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
  EXPECT_EQ(ReadAll(emu->flash_path()), before) << "nothing written";
  EXPECT_FALSE(emu->AwaitLog("DfuSe bootloader running", 1, std::chrono::milliseconds(0)))
      << emu->Log();
  ExpectApplicationBackCalibrated();
}

}  // namespace
}  // namespace vibid::hil
