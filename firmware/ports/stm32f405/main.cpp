// The DAQ board image: clocks, watchdog, timer-triggered sampling, the firmware core, and the
// USB device (HID report link + DFU run-time) on OTG_FS.
#include <array>
#include <cstdint>

#include "board_led.hpp"
#include "board_port.hpp"
#include "calibration_flash.hpp"
#include "clock.hpp"
#include "crystal_check.hpp"
#include "otg_fs_dcd.hpp"
#include "regs/core_m4.hpp"
#include "sampler.hpp"
#include "system.hpp"
#include "vibid/shared/board_profile.hpp"
#include "vibid/fw/core.hpp"
#include "vibid/fw/usb/device.hpp"
#include "vibid/fw/usb/dfu_runtime.hpp"
#include "vibid/fw/usb/hid_class.hpp"

namespace vibid::fw::stm32 {
namespace {

/// The acquisition log: the largest block the RAM budget leaves (SRAM; CCM holds the stack). Its
/// size is part of the board profile the emulator and the host's preflight use.
constexpr std::size_t kLogBytes = vibid::kBoardProfile.log_bytes;

class DfuOnDetach final : public usb::DfuDetachHandler {
 public:
  explicit DfuOnDetach(SystemControl& system) : system_(system) {}
  void OnDetach(std::uint16_t) override { system_.EnterDfu(); }

 private:
  SystemControl& system_;
};

OtgFsDcd g_dcd;
Sampler g_sampler;
std::array<std::uint8_t, kLogBytes> g_log;

}  // namespace
}  // namespace vibid::fw::stm32

extern "C" void OTG_FS_IRQHandler() { vibid::fw::stm32::g_dcd.HandleInterrupt(); }
extern "C" void DMA2_Stream0_IRQHandler() { vibid::fw::stm32::g_sampler.HandleDmaInterrupt(); }
extern "C" void ADC_IRQHandler() { vibid::fw::stm32::g_sampler.HandleAdcInterrupt(); }
extern "C" void SysTick_Handler() {
  vibid::fw::stm32::OnSysTick();
  vibid::fw::stm32::g_sampler.TrackEncoders();
}

int main() {
  using namespace vibid::fw;
  using namespace vibid::fw::stm32;

  // Interrupts stay masked (since the reset handler, which also made sure this is a clean start:
  // nothing from a bootloader is pending or configured) until every handler's driver is set up.
  // The watchdog goes first: every step after it is bounded by it.
  DisableInterrupts();
#if !defined(NDEBUG)
  // Debug builds are the ones run under a debugger: a breakpoint must not reset the board.
  FreezeWatchdogWhenHalted();
#endif
  StartWatchdog(kWatchdogTimeoutMs);
  static BoardSystemControl system;
  system.Init();
  // Below 2.7 V the 5 wait states ConfigureClocks sets are too few for 168 MHz (RM0090 table 10):
  // the brown-out reset at level 3 holds the chip in reset there instead. Still on the HSI at
  // 0 wait states, where any supply from 1.8 V is fine.
  (void)EnsureBrownOutLevel3();
  const ClockConfig clocks = ConfigureClocks();
  // The LSE starts now and is ready (up to 2 s) long before a self-test measures against it.
  if (BoardHasLse()) StartLse();
  LightBoardLed();
  StartMillisecondTick(clocks.sysclk_hz);
  g_sampler.Init(clocks);
  EnableInterrupts();

  static SysTickClock clock;
  static InternalCalibrationFlash flash;
  static usb::HidClass hid;
  static Core core(Port{clock, g_sampler, flash, system}, hid, g_log);
  (void)core.Boot();

  static const std::array<char, 25> serial = BoardIdHex();
  static DfuOnDetach detach{system};
  static usb::DfuRuntime dfu{detach};
  static const std::array<usb::ClassDriver*, 2> drivers = {&hid, &dfu};
  static const usb::DaqStrings strings = usb::MakeDaqStrings(serial.data());
  static usb::UsbDevice device{g_dcd, drivers, usb::DaqDescriptors(strings)};
  system.AttachUsb(g_dcd);
  system.AttachSampler(g_sampler);
  system.AttachImage(OwnImage());
  system.AttachClock(clocks, BoardHasLse());
  system.AttachSamplerCounters(g_sampler.counters());
  // On the HSI fallback the PLL gives USB its 48 MHz from the HSI (+-1 % at 25 C, outside USB's
  // +-0.25 %: a host may not take it), so the board can enumerate and get-info say why it
  // refuses to acquire. A PLL that did not lock at all leaves it off the bus; the LED blinks
  // either way.
  // On the HSI the turnaround is set for its slowest (-8 %, 14.72 MHz: TRDT 0xF).
  const std::uint32_t ahb_min_hz = clocks.source == ClockSource::kPllFromHse
                                       ? clocks.sysclk_hz
                                       : kHsiHz / 1000 * kHsiSlowestPermille;
  g_dcd.Configure(OtgFsConfig{
      .ahb_hz = clocks.sysclk_hz, .ahb_min_hz = ahb_min_hz, .vbus_sensing = BoardSensesVbus()});
  if (clocks.usb_clocked) (void)device.Start();
  const bool on_crystal = clocks.source == ClockSource::kPllFromHse;

  std::uint32_t bus_resets = 0;
  bool was_suspended = false;
  for (;;) {
    device.Task();
    if (device.counters().bus_resets != bus_resets) {
      bus_resets = device.counters().bus_resets;
      core.OnLinkReset();
    }
    core.Poll();
    // A suspended bus leaves the device 2.5 mA from VBUS (USB 2.0 §7.2.3): the status LED, a few
    // mA of it, goes dark until the host resumes (the OTG driver stops the PHY clock).
    if (device.suspended()) {
      SetBoardLed(false);
    } else if (!on_crystal || device.suspended() != was_suspended) {
      SetBoardLed(StatusLedLit(on_crystal, MicrosecondsSinceBoot()));
    }
    was_suspended = device.suspended();
    KickWatchdog();
    WaitForInterrupt();
  }
}
