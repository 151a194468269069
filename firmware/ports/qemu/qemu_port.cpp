#include "qemu_port.hpp"

#include <algorithm>

#include "image_crc_self_test.hpp"
#include "regs/core_m4.hpp"
#include "regs/peripherals.hpp"
#include "regs/rcc.hpp"
#include "system.hpp"

namespace vibid::fw::qemu {

using namespace vibid::fw::stm32;

namespace {
constexpr Address kTim5 = 0x40000C00;
constexpr std::uint32_t kApb1Tim5 = Bit(3);
constexpr std::uint32_t kTimerClockHz = 48000000;  // QEMU's fixed TIM2..5 kernel clock.

}  // namespace

void TimerClock::Init() {
  Reg(rcc::kApb1enr) |= kApb1Tim5;
  Reg(kTim5 + tim::kCr1) = 0;
  Reg(kTim5 + tim::kPsc) = kTimerClockHz / 1000000 - 1;
  Reg(kTim5 + tim::kArr) = 0xFFFFFFFF;
  Reg(kTim5 + tim::kEgr) = tim::kEgrUg;
  Reg(kTim5 + tim::kCnt) = 0;
  Reg(kTim5 + tim::kCr1) = tim::kCr1Cen;
}

std::uint64_t TimerClock::NowUs() const {
  CriticalSection lock;
  const std::uint32_t now = Reg(kTim5 + tim::kCnt);
  if (now < last_) high_ += std::uint64_t{1} << 32;
  last_ = now;
  return high_ | now;
}

RamCalibrationFlash::RamCalibrationFlash() {
  for (auto& s : slots_) s.fill(kErasedByte);
}

Status RamCalibrationFlash::Erase(Slot slot) {
  slots_[static_cast<std::size_t>(slot)].fill(kErasedByte);
  return Status::kOk;
}

Status RamCalibrationFlash::Program(Slot slot, std::size_t offset,
                                    std::span<const std::uint8_t> data) {
  if (offset > kSlotBytes || data.size() > kSlotBytes - offset) return Status::kOutOfRange;
  auto& s = slots_[static_cast<std::size_t>(slot)];
  for (std::size_t i = 0; i < data.size(); ++i) s[offset + i] &= data[i];
  return Status::kOk;
}

Status RamCalibrationFlash::Read(Slot slot, std::size_t offset, std::span<std::uint8_t> out) const {
  if (offset > kSlotBytes || out.size() > kSlotBytes - offset) return Status::kOutOfRange;
  const auto& s = slots_[static_cast<std::size_t>(slot)];
  std::copy_n(s.begin() + static_cast<std::ptrdiff_t>(offset), out.size(), out.begin());
  return Status::kOk;
}

void QemuSystemControl::Init() { reset_cause_ = ReadAndClearResetCause(); }
void QemuSystemControl::Reset() { SystemReset(); }

SystemControl::SelfTestMeasurement QemuSystemControl::MeasureSelfTest(
    wire::SelfTestCheck check, std::uint32_t sample_period_us) {
  (void)sample_period_us;
  if (check == wire::SelfTestCheck::kImageCrc) return stm32::ImageCrcMeasurement(image_);
  return {};
}
void QemuSystemControl::EnterDfu() { SystemReset(); }

}  // namespace vibid::fw::qemu
