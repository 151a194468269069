// Calibration flash on the fake register file: x32 erase and program (RM0090 §3.6), the
// watchdog fed right before the erase (which stalls the CPU) and during programming, and the cache
// reset after an erase as ST's HAL (FLASH_FlushCaches) does it.
#include <array>

#include "calibration_flash.hpp"
#include "port_test_fixture.hpp"
#include "regs/peripherals.hpp"
#include "regs/rcc.hpp"
#include "system.hpp"

namespace vibid::fw::stm32::test {
namespace {

constexpr Address kSlot0 = 0x08008000;
constexpr std::uint32_t kAcrRunning = 5 | flash::kAcrIcen | flash::kAcrDcen;  // as ConfigureClocks

class CalibrationFlashTest : public PortTest {
 protected:
  /// FLASH_SR flags are write-1-to-clear (RM0090 §3.9.4).
  static void ModelStatusRegister() {
    regs().OnWrite(flash::kSr, [](std::uint32_t held, std::uint32_t w) { return held & ~w; });
  }
  void SetUp() override {
    PortTest::SetUp();
    regs().Poke(flash::kCr, flash::kCrLock);
    regs().Poke(flash::kAcr, kAcrRunning);
    ModelStatusRegister();
    // Erased flash; NOR programming can only clear bits.
    for (Address a = kSlot0; a < kSlot0 + InternalCalibrationFlash::kSlotBytes; a += 4) {
      regs().Poke(a, 0xFFFFFFFF);
      regs().OnWrite(a, [](std::uint32_t held, std::uint32_t written) { return held & written; });
    }
  }
  InternalCalibrationFlash flash_;
};

TEST_F(CalibrationFlashTest, EraseSequence) {
  ASSERT_EQ(flash_.Erase(CalibrationFlash::Slot{0}), Status::kOk);
  const auto& log = regs().log();
  // Unlock keys (RM0090 §3.5.1).
  const std::size_t key1 = regs().FindWrite(flash::kKeyr, 0x45670123);
  const std::size_t key2 = regs().FindWrite(flash::kKeyr, 0xCDEF89AB, key1);
  ASSERT_NE(key2, kNone);
  // SER (bit 1) | PSIZE x32 (10 in 9:8) | SNB 2 (6:3) = 0x2 | 0x200 | 0x10 = 0x212, then STRT.
  const std::size_t setup = regs().FindWrite(flash::kCr, 0x212, key2);
  const std::size_t start = regs().FindWrite(flash::kCr, 0x212 | flash::kCrStrt, setup);
  ASSERT_NE(setup, kNone);
  ASSERT_NE(start, kNone);
  // The watchdog is fed between the set-up and the start: a full period for the erase.
  const std::size_t feed = regs().FindWrite(iwdg::kKr, 0xAAAA, setup);
  EXPECT_LT(feed, start);
  // After the erase: CR cleared, locked, then each cache disabled, reset, re-enabled.
  const std::size_t lock = regs().FindWrite(flash::kCr, flash::kCrLock, start);
  ASSERT_NE(lock, kNone);
  std::vector<std::uint32_t> acr;
  for (std::size_t i = start; i < log.size(); ++i) {
    if (log[i].kind == Access::Kind::kWrite && log[i].address == flash::kAcr)
      acr.push_back(log[i].value);
  }
  const std::uint32_t ic = flash::kAcrIcen, dc = flash::kAcrDcen;
  const std::uint32_t icrst = Bit(11), dcrst = Bit(12);  // RM0090 §3.9.1 FLASH_ACR
  EXPECT_EQ(acr,
            (std::vector<std::uint32_t>{
                kAcrRunning & ~ic, (kAcrRunning & ~ic) | icrst, kAcrRunning & ~ic, kAcrRunning,
                kAcrRunning & ~dc, (kAcrRunning & ~dc) | dcrst, kAcrRunning & ~dc, kAcrRunning}));
}

/// Each SysTick read is `ms` milliseconds later.
void AdvanceClockPerRead(std::uint32_t ms) {
  FakeRegisters::Get().OnRead(systick::kVal, [ms](std::uint32_t held) {
    for (std::uint32_t i = 0; i < ms; ++i) OnSysTick();
    return held;
  });
}

TEST_F(CalibrationFlashTest, EraseRunsOnOneWatchdogPeriodAndTimesOutWithinIt) {
  regs().LogReads(false);
  AdvanceClockPerRead(1);
  // BSY for 500 status reads a millisecond apart (the datasheet's worst x32 erase), then done.
  // The CPU stalls on flash fetches while the array erases, so nothing is fed during the wait:
  // one feed right before STRT, one after.
  std::uint32_t polls = 0;
  regs().OnRead(flash::kSr, [&polls](std::uint32_t held) {
    const bool started = (FakeRegisters::Get().Peek(flash::kCr) & flash::kCrStrt) != 0;
    if (!started) return held;
    return ++polls <= 500 ? held | flash::kSrBsy : held;
  });
  ASSERT_EQ(flash_.Erase(CalibrationFlash::Slot{1}), Status::kOk);
  const std::size_t start = regs().FindWriteWithBits(flash::kCr, flash::kCrStrt);
  std::size_t feeds_after_start = 0;
  for (std::size_t i = start; i < regs().log().size(); ++i) {
    const Access& a = regs().log()[i];
    feeds_after_start +=
        a.kind == Access::Kind::kWrite && a.address == iwdg::kKr && a.value == 0xAAAA;
  }
  EXPECT_EQ(feeds_after_start, 1U);
  EXPECT_LT(regs().FindWrite(iwdg::kKr, 0xAAAA), start);
  // SNB 3 for slot 1.
  EXPECT_NE(regs().FindWrite(flash::kCr, 0x21A), kNone);

  // A sector that never finishes: an error after 900 ms, inside the watchdog's 1.0 s (the
  // datasheet's worst erase is 500 ms at x32, 800 ms at x8), and the flash locked again.
  regs().Clear();
  ModelStatusRegister();
  AdvanceClockPerRead(100);  // 100 ms per poll: the bound is passed at the 10th
  regs().OnRead(flash::kSr, [](std::uint32_t held) {
    const bool started = (FakeRegisters::Get().Peek(flash::kCr) & flash::kCrStrt) != 0;
    return started ? held | flash::kSrBsy : held;
  });
  EXPECT_EQ(flash_.Erase(CalibrationFlash::Slot{0}), Status::kInternal);
  EXPECT_EQ(flash_.errors(), 1U);
  EXPECT_EQ(regs().Peek(flash::kCr), flash::kCrLock);
  std::size_t clock_reads = 0;
  for (const Access& a : regs().log())
    clock_reads += a.kind == Access::Kind::kRead && a.address == systick::kVal;
  EXPECT_EQ(clock_reads, 11U);  // the start, then 100 .. 1000 ms: 1000 > 900 ends it
  EXPECT_EQ(regs().WritesTo(iwdg::kKr).size(), 2U);
}

TEST_F(CalibrationFlashTest, ProgramsWordsWithUnalignedEdgesPadded) {
  const std::array<std::uint8_t, 5> data = {0x12, 0x34, 0x56, 0x78, 0x9A};
  ASSERT_EQ(flash_.Program(CalibrationFlash::Slot{0}, 1, data), Status::kOk);
  // PG | PSIZE x32 = 0x201; byte 0 and bytes 6..7 padded with 0xFF (little-endian words).
  EXPECT_NE(regs().FindWrite(flash::kCr, 0x201), kNone);
  EXPECT_EQ(regs().WritesTo(kSlot0), std::vector<std::uint32_t>{0x563412FF});
  EXPECT_EQ(regs().WritesTo(kSlot0 + 4), std::vector<std::uint32_t>{0xFFFF9A78});
  for (const Access& a : regs().log()) {
    if (a.kind == Access::Kind::kWrite && a.address >= kSlot0 && a.address < kSlot0 + 0x4000) {
      EXPECT_EQ(a.width, 4U) << "x32 parallelism takes word writes only (PGPERR otherwise)";
    }
  }
  std::array<std::uint8_t, 8> back{};
  ASSERT_EQ(flash_.Read(CalibrationFlash::Slot{0}, 0, back), Status::kOk);
  EXPECT_EQ(back, (std::array<std::uint8_t, 8>{0xFF, 0x12, 0x34, 0x56, 0x78, 0x9A, 0xFF, 0xFF}));
  EXPECT_EQ(regs().Peek(flash::kCr), flash::kCrLock);
}

TEST_F(CalibrationFlashTest, WholeSlotProgramFeedsTheWatchdogEvery256Writes) {
  regs().LogReads(false);
  std::vector<std::uint8_t> data(InternalCalibrationFlash::kSlotBytes, 0x5A);
  ASSERT_EQ(flash_.Program(CalibrationFlash::Slot{0}, 0, data), Status::kOk);
  // 4096 words / 256 = 16 feeds.
  EXPECT_EQ(regs().WritesTo(iwdg::kKr).size(), 16U);
  EXPECT_EQ(regs().Peek(kSlot0 + 0x3FFC), 0x5A5A5A5AU);
}

TEST_F(CalibrationFlashTest, LowVoltageBoardsUseByteParallelism) {
  InternalCalibrationFlash x8(InternalCalibrationFlash::Parallelism::kX8);
  ASSERT_EQ(x8.Erase(CalibrationFlash::Slot{0}), Status::kOk);
  // SER | PSIZE x8 (00) | SNB 2 = 0x12.
  EXPECT_NE(regs().FindWrite(flash::kCr, 0x12 | flash::kCrStrt), kNone);
  const std::size_t before = regs().log().size();
  const std::array<std::uint8_t, 3> data = {0xA1, 0xB2, 0xC3};
  ASSERT_EQ(x8.Program(CalibrationFlash::Slot{0}, 5, data), Status::kOk);
  EXPECT_NE(regs().FindWrite(flash::kCr, flash::kCrPg, before), kNone);  // PG, PSIZE 00
  std::vector<Address> written;
  for (std::size_t i = before; i < regs().log().size(); ++i) {
    const Access& a = regs().log()[i];
    if (a.kind != Access::Kind::kWrite || a.address < kSlot0 || a.address >= kSlot0 + 0x4000)
      continue;
    EXPECT_EQ(a.width, 1U);
    written.push_back(a.address);
  }
  EXPECT_EQ(written, (std::vector<Address>{kSlot0 + 5, kSlot0 + 6, kSlot0 + 7}));
  EXPECT_EQ(regs().Peek(kSlot0 + 4), 0xC3B2A1FFU);
}

TEST_F(CalibrationFlashTest, ReadBackMismatchIsAnError) {
  // A cell that does not take the new value (worn or protected).
  regs().OnWrite(kSlot0, [](std::uint32_t held, std::uint32_t) { return held; });
  const std::array<std::uint8_t, 4> data = {1, 2, 3, 4};
  EXPECT_EQ(flash_.Program(CalibrationFlash::Slot{0}, 0, data), Status::kInternal);
  EXPECT_EQ(flash_.errors(), 1U);
  EXPECT_EQ(flash_.Program(CalibrationFlash::Slot{0}, 16 * 1024 - 2, data), Status::kOutOfRange);
}

}  // namespace
}  // namespace vibid::fw::stm32::test
