// The board image for qemu-system-arm -M netduinoplus2 (STM32F405): the same core and the same
// chip support as the DAQ board, with the peripherals QEMU does not model replaced: reports
// travel framed over USART1 instead of USB, samples are injected by the host instead of
// converted, and the calibration slots are RAM. Run it with -icount for deterministic timing.
#include <array>
#include <cstdint>

#include "diagnostics.hpp"
#include "injected_frames.hpp"
#include "qemu_port.hpp"
#include "regs/core_m4.hpp"
#include "system.hpp"
#include "usart_link.hpp"
#include "vibid/fw/core.hpp"
#include "vibid/shared/wire/commands.hpp"

namespace vibid::fw::qemu {
namespace {

// netduinoplus2 runs the core at 168 MHz; the USARTs sit on APB2 (84 MHz) on silicon.
constexpr std::uint32_t kCoreClockHz = 168000000;
constexpr std::uint32_t kUsartClockHz = 84000000;
constexpr std::uint32_t kBaud = 115200;
/// The acquisition log: QEMU has no CCM, so the RAM calibration slots, the decimator state and
/// the stack share the 128 KiB SRAM with it: smaller than the board profile's 96 KiB, and get-info
/// says so (the host's budget reads the log size from there). The link is the USART, not USB.
constexpr std::size_t kLogBytes = 56 * 1024;
/// A diagnostics line every this many delivered frames.
constexpr std::uint32_t kDiagnosticsEveryFrames = 500;

/// The inject-frames port command: frames from the host into the sample queue.
class InjectionCommands final : public PortCommandHandler {
 public:
  explicit InjectionCommands(InjectedFrameSource& source) : source_(source) {}

  Status HandlePortCommand(std::uint8_t command, std::span<const std::uint8_t> request,
                           std::span<std::uint8_t, wire::kMaxPayload>,
                           std::size_t& response_length) override {
    response_length = 0;
    if (command != static_cast<std::uint8_t>(wire::Command::kInjectFrames))
      return Status::kUnimplemented;
    wire::InjectFramesRequest frames;
    if (const Status s = wire::Decode(request, frames); s != Status::kOk) return s;
    // kUnavailable when the queue is full: the host sends the same frames again later.
    return source_.Inject(std::span(frames.raw).first(frames.frame_count));
  }

 private:
  InjectedFrameSource& source_;
};

UsartReportLink g_link;
InjectedFrameSource g_source;
std::array<std::uint8_t, kLogBytes> g_log;
RamCalibrationFlash g_flash;

void ReportSamplingCost() {
  static std::uint32_t reported = 0;
  const std::uint32_t frames = g_source.delivered_frames();
  if (frames < reported + kDiagnosticsEveryFrames) {
    if (frames < reported) reported = 0;  // A new acquisition restarted the count.
    return;
  }
  reported = frames;
  static constexpr const char* kLabels[] = {"frames", "starved_ticks", "isr_cycles",
                                            "link_crc_errors"};
  const std::uint64_t values[] = {frames, g_source.starved_ticks(), g_source.handler_cycles(),
                                  g_link.DecoderCounters().crc_errors};
  DiagnosticsValues(kLabels, values, 4);
}

}  // namespace
}  // namespace vibid::fw::qemu

extern "C" void USART1_IRQHandler() { vibid::fw::qemu::g_link.HandleInterrupt(); }
extern "C" void SysTick_Handler() { (void)vibid::fw::qemu::g_source.HandleTick(); }

int main() {
  using namespace vibid::fw;
  using namespace vibid::fw::qemu;

  static QemuSystemControl system;
  system.Init();
  system.AttachImage(stm32::OwnImage());
  // The board's flash set-up (caches on, prefetch off), so this image runs what the board runs;
  // QEMU ignores FLASH_ACR and counts instructions, not wait states.
  (void)stm32::ConfigureFlashAccess(5);
  // SysTick: 1 kHz while idle (wakes the main loop), the sample rate while acquiring.
  g_source.Init(kCoreClockHz, 1000);
  DiagnosticsInit();

  static TimerClock clock;
  clock.Init();
  g_link.Init(kUsartClockHz, kBaud);
  // The reset handler left interrupts masked; SysTick and USART1 have their drivers now.
  stm32::EnableInterrupts();
  static InjectionCommands injection{g_source};
  static Core core(Port{clock, g_source, g_flash, system}, g_link, g_log, &injection);
  (void)core.Boot();
  // The host waits for this line: bytes sent before USART1 is enabled would be dropped.
  DiagnosticsLine("vibid qemu image: ready");

  for (;;) {
    core.Poll();
    ReportSamplingCost();
    stm32::WaitForInterrupt();
  }
}
