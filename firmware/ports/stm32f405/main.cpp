// The DAQ board image: clocks, watchdog, sampling, USB HID + DFU run-time on OTG_FS.
#include <array>
#include <cstdint>

#include "calibration_flash.hpp"
#include "clock.hpp"
#include "otg_fs_dcd.hpp"
#include "regs/core_m4.hpp"
#include "sampler.hpp"
#include "system.hpp"
#include "vibid/fw/usb/device.hpp"
#include "vibid/fw/usb/dfu_runtime.hpp"
#include "vibid/fw/usb/hid_class.hpp"

namespace vibid::fw::stm32 {
namespace {

constexpr std::uint32_t kWatchdogTimeoutMs = 500;
constexpr std::uint32_t kDefaultSampleRateHz = 5000;

class BootloaderOnDetach final : public usb::DfuDetachHandler {
 public:
  void OnDetach(std::uint16_t) override { RebootToBootloader(); }
};

struct LatestFrame {
  volatile std::uint32_t sequence = 0;
  RawFrame frame{};
};

void StoreFrame(const RawFrame& frame, void* context) {
  auto* latest = static_cast<LatestFrame*>(context);
  latest->frame = frame;
  latest->sequence = frame.sequence;
}

OtgFsDcd g_dcd;
Sampler g_sampler;
LatestFrame g_latest;

}  // namespace
}  // namespace vibid::fw::stm32

extern "C" void OTG_FS_IRQHandler() { vibid::fw::stm32::g_dcd.HandleInterrupt(); }
extern "C" void DMA2_Stream0_IRQHandler() { vibid::fw::stm32::g_sampler.HandleDmaInterrupt(); }
extern "C" void SysTick_Handler() { vibid::fw::stm32::OnSysTick(); }

int main() {
  using namespace vibid::fw::stm32;
  namespace usb = vibid::fw::usb;

  const ResetCause reset_cause = ReadAndClearResetCause();
  (void)reset_cause;
  const ClockConfig clocks = ConfigureClocks();
  StartMillisecondTick(clocks.sysclk_hz);
  StartWatchdog(kWatchdogTimeoutMs);

  (void)g_sampler.Configure(clocks.apb1_timer_hz, kDefaultSampleRateHz, StoreFrame, &g_latest);

  static const std::array<char, 25> serial = BoardIdHex();
  static usb::HidClass hid;
  static BootloaderOnDetach detach;
  static usb::DfuRuntime dfu{detach};
  static const std::array<usb::ClassDriver*, 2> drivers = {&hid, &dfu};
  static usb::UsbDevice device{g_dcd, drivers, serial.data()};
  // Without the 48 MHz PLL clock the OTG core cannot run; the board then stays off the bus and
  // the watchdog keeps it alive for a retry after the next reset.
  if (clocks.source == ClockSource::kPllFromHse) (void)device.Start();

  for (;;) {
    device.Task();
    KickWatchdog();
    WaitForInterrupt();
  }
}
