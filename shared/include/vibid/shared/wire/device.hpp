// Facts about the board that travel on the wire: its sample channels, reset causes and
// capability bits. Values are part of the protocol: append only, never renumber.
#pragma once

#include <cstddef>
#include <cstdint>

namespace vibid::wire {

/// The six sample channels, in frame and log order. A channel mask bit i selects Channel(i).
enum class Channel : std::uint8_t {
  kForce1 = 0,    ///< Load cell 1 (hammer or shaker), raw ADC code.
  kForce2 = 1,    ///< Load cell 2 (hand push), raw ADC code.
  kAccel1 = 2,    ///< Accelerometer on mass 1, raw ADC code.
  kAccel2 = 3,    ///< Accelerometer on mass 2, raw ADC code.
  kEncoder1 = 4,  ///< Encoder 1, signed position count (extended to 32 bits by the port).
  kEncoder2 = 5,  ///< Encoder 2, signed position count.
};

inline constexpr std::size_t kChannelCount = 6;
inline constexpr std::uint8_t kAllChannelsMask = (1u << kChannelCount) - 1u;

/// What a channel measures; get-info lists one per channel.
enum class ChannelKind : std::uint8_t {
  kLoadCell = 1,
  kAccelerometer = 2,
  kEncoder = 3,
};

constexpr ChannelKind KindOf(Channel c) {
  switch (c) {
    case Channel::kForce1:
    case Channel::kForce2: return ChannelKind::kLoadCell;
    case Channel::kAccel1:
    case Channel::kAccel2: return ChannelKind::kAccelerometer;
    case Channel::kEncoder1:
    case Channel::kEncoder2: return ChannelKind::kEncoder;
  }
  return ChannelKind::kLoadCell;
}

/// Log format of the converter channels (load cells, accelerometers): unsigned 16 bits holding
/// the 12-bit code with 4 fraction bits ("12.4", code << 4). Raw samples fill the integer part; a
/// decimated record keeps the resolution the anti-aliasing filter's averaging gained.
inline constexpr unsigned kLogAdcFractionBits = 4;
inline constexpr std::int32_t kLogAdcMax = 0xFFFF;

/// Bytes a channel takes in a log record: 2 for converter channels, 4 for encoder counts.
constexpr std::size_t LogValueBytes(Channel c) {
  return KindOf(c) == ChannelKind::kEncoder ? 4 : 2;
}

constexpr bool IsLoadCell(std::uint8_t channel_index) {
  return channel_index == static_cast<std::uint8_t>(Channel::kForce1) ||
         channel_index == static_cast<std::uint8_t>(Channel::kForce2);
}

/// Why the board last started (get-info). Ports map their reset flags onto these.
enum class ResetCause : std::uint8_t {
  kUnknown = 0,
  kPowerOn = 1,
  kPin = 2,       ///< External reset pin (NRST).
  kSoftware = 3,  ///< The reset command or an explicit software reset.
  kWatchdog = 4,  ///< Independent or window watchdog.
  kBrownOut = 5,
  kLowPower = 6,
  /// A fault or an unexpected exception reset the board; get-info page kInfoPageFault holds
  /// what the fault handler recorded (firmware before it reported kSoftware).
  kFault = 7,
};

/// The supply level below which the board holds itself in reset (get-info). STM32F405: the
/// option bytes' BOR_LEV (RM0090 §3.9.10); the thresholds are the datasheet's nominal ones.
enum class BrownOut : std::uint8_t {
  kUnknown = 0,  ///< Not reported (the emulator, the QEMU image).
  kOff = 1,      ///< Power-on/power-down reset only (about 1.8 V): the STM32's factory setting.
  kLevel1 = 2,   ///< About 2.1 V.
  kLevel2 = 3,   ///< About 2.4 V.
  kLevel3 = 4,   ///< 2.75-2.88 V (DS8626): above the 2.7 V x32 flash programming takes.
};

/// Where the board's system clock comes from (get-info health page). A board on its internal
/// oscillator refuses acquisitions (its sample clock would be off by up to the oscillator's
/// tolerance, reason internal-clock) but still answers, so the host can read why.
enum class ClockState : std::uint8_t {
  kUnknown = 0,                ///< Not reported (the emulator, the QEMU image).
  kCrystal = 1,                ///< The PLL runs from the crystal the image was built for.
  kCrystalDidNotStart = 2,     ///< No HSE ready in time: on the internal oscillator.
  kCrystalWrongFrequency = 3,  ///< The HSE read outside 95..109 % of the build's: internal.
  kPllDidNotLock = 4,          ///< The PLL or the switch to it did not complete: internal.
};

/// Which hardware answers. The emulator and the QEMU image name themselves so the host can tell.
enum class BoardId : std::uint16_t {
  kStm32f405 = 1,
  kQemuNetduinoPlus2 = 2,
  kEmulator = 3,
  kHostTest = 0xFFFF,  ///< Unit-test fakes.
};

/// get-info capability bits.
inline constexpr std::uint32_t kCapDob = 1u << 0;             ///< Runs the fixed-point DOB.
inline constexpr std::uint32_t kCapForceTrigger = 1u << 1;    ///< Force-threshold trigger.
inline constexpr std::uint32_t kCapDfu = 1u << 2;             ///< enter-DFU reaches a bootloader.
inline constexpr std::uint32_t kCapScenarioSelect = 1u << 3;  ///< Emulator only: select-scenario.
inline constexpr std::uint32_t kCapSampleInjection =
    1u << 4;  ///< QEMU image: samples arrive over the link.

}  // namespace vibid::wire
