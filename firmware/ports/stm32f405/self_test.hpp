// Self-test measurements the STM32F405 port takes on its own registers: the encoder timers'
// state, the crystal against the host's USB start-of-frame, VDDA from VREFINT, and the analog
// channels' idle codes through the acquisitions' own sampler.
#pragma once

#include <cstdint>

#include "idle_statistics.hpp"
#include "regs/mmio.hpp"
#include "vibid/fw/port.hpp"

namespace vibid::fw::stm32 {

/// An encoder timer's state: running when CR1 CEN is set and SMCR SMS selects encoder mode 3,
/// as the sampler configures it (RM0090 §18.4.1 TIMx_CR1, §18.4.3 TIMx_SMCR); count: TIMx_CNT
/// (§18.4.10).
struct EncoderState {
  bool running = false;
  std::uint32_t count = 0;
};
EncoderState ReadEncoder(Address timer);

/// Frames the crystal check counts over: 1 s, so a detection latency of a few core cycles at
/// either end weighs well under 0.1 ppm.
inline constexpr std::uint32_t kCrystalCheckFrames = 1000;

/// The crystal's error in milli-ppm from `cycles` core cycles counted over `frames` USB frames
/// of 1 ms: the core runs from the HSE through the PLL, so a crystal fast by e counts
/// sysclk/1000 x (1 + e) cycles per frame. Scaling: cycles - nominal < 2^32 and x 10^9 stays
/// within int64 (< 4.3e18 < 9.2e18).
constexpr std::int64_t CrystalErrorMilliPpm(std::uint32_t cycles, std::uint32_t frames,
                                            std::uint32_t sysclk_hz) {
  const std::int64_t nominal = static_cast<std::int64_t>(frames) * (sysclk_hz / 1000);
  return (static_cast<std::int64_t>(cycles) - nominal) * 1'000'000'000 / nominal;
}

/// Counts core cycles (DWT CYCCNT) from one start-of-frame flag (OTG_FS GINTSTS SOF) to the one
/// `frames` later, polling the flag and clearing it; the OTG interrupt leaves SOF alone (it is
/// not in GINTMSK). Each frame is awaited at most 2 ms, and the watchdog is fed.
/// @returns false when a frame does not come in time (no host, or the bus is suspended).
bool CountCyclesOverFrames(std::uint32_t frames, std::uint32_t sysclk_hz, std::uint32_t& cycles);

/// VREFINT_CAL: VREFINT's conversion at VDDA = 3.3 V and 30 C, taken in production and kept in
/// system memory at 0x1FFF7A2A..0x1FFF7A2B (STM32F405 datasheet, "Internal reference voltage
/// calibration values"). Read as the upper half of the word at 0x1FFF7A28.
inline constexpr Address kVrefintCalWord = 0x1FFF7A28;
std::uint16_t VrefintCal();

/// VDDA in mV: VREFINT is a fixed voltage, so its code scales as 1 / VDDA:
/// VDDA = 3300 mV x VREFINT_CAL / VREFINT_DATA, rounded to the nearest mV. 0 for a code of 0.
constexpr std::uint32_t VddaMillivolts(std::uint16_t vrefint_cal, std::uint32_t vrefint_code) {
  if (vrefint_code == 0) return 0;
  return (3300u * vrefint_cal + vrefint_code / 2) / vrefint_code;
}

/// Conversions averaged for VDDA.
inline constexpr std::uint32_t kVrefintConversions = 16;

/// Converts VREFINT (ADC1 channel 17) kVrefintConversions times by software start and returns
/// the mean code (rounded). ADC1 and the common CCR are set for it (independent mode, TSVREFE,
/// 480-cycle sampling: 22.9 us at ADCCLK 21 MHz, above VREFINT's 10 us minimum) and put back as
/// they were; only while idle (the sampler owns the converters while sampling).
/// @returns false when a conversion does not end in time.
bool ConvertVrefint(std::uint32_t sysclk_hz, std::uint32_t& mean_code);

/// The longest the idle sampling may block the main loop: as long as the crystal check's second.
/// kSelfTestSamples frames at a longer configured period (above 1 ms) are not taken.
inline constexpr std::uint64_t kMaxIdleSamplingUs = 1'000'000;
/// Slack on the frames' own time before the sampling is given up: the first edge comes at the
/// start, so a sampler that delivers is done long before.
inline constexpr std::uint64_t kIdleSamplingSlackUs = 100'000;

enum class IdleSampling : std::uint8_t {
  kOk,
  kTooLong,     ///< frames x period above kMaxIdleSamplingUs.
  kRefused,     ///< The sampler refused to start (running, or a period it cannot make).
  kIncomplete,  ///< Fewer frames than asked within their time plus kIdleSamplingSlackUs.
};

/// Runs the acquisitions' sampler (TIM2 edges, ADC1-3, DMA2 stream 0; sampler.hpp) at
/// `sample_period_us` for `frames` frames and adds analog channel `channel`'s codes (wire::Channel
/// order, 0..3) to `sums`; the main loop waits, feeding the watchdog, and stops the sampler in
/// every case. Only while idle: a running sampler refuses to start (kRefused).
IdleSampling SampleIdleChannel(FrameSource& sampler, std::uint32_t sample_period_us,
                               unsigned channel, std::uint32_t frames, CodeSums& sums);

}  // namespace vibid::fw::stm32
