// DFU 1.1 (USB Device Firmware Upgrade) and ST's DfuSe extension of it (UM0424), as every end of
// the project speaks them: the firmware's run-time interface, the host's DfuSe client and the
// emulator's bootloader. Values are the specifications'. Plain constexpr: the firmware uses it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

namespace vibid::dfu {

/// Class request codes (DFU 1.1 table 3.2).
enum class Request : std::uint8_t {
  kDetach = 0,
  kDnload = 1,
  kUpload = 2,
  kGetStatus = 3,
  kClrStatus = 4,
  kGetState = 5,
  kAbort = 6,
};

/// bState (DFU 1.1 §6.1.2): appIDLE and appDETACH are the run-time states, the rest DFU mode's.
enum class State : std::uint8_t {
  kAppIdle = 0,
  kAppDetach = 1,
  kIdle = 2,
  kDnloadSync = 3,
  kDnBusy = 4,
  kDnloadIdle = 5,
  kManifestSync = 6,
  kManifest = 7,
  kManifestWaitReset = 8,
  kUploadIdle = 9,
  kError = 10,
};

/// bStatus (DFU 1.1 §6.1.2): what the last request came to.
enum class Status : std::uint8_t {
  kOk = 0x00,
  kErrTarget = 0x01,  ///< Not for this device; DfuSe: an unknown command.
  kErrFile = 0x02,
  kErrWrite = 0x03,
  kErrErase = 0x04,
  kErrCheckErased = 0x05,
  kErrProg = 0x06,
  kErrVerify = 0x07,   ///< The written memory does not read back as sent.
  kErrAddress = 0x08,  ///< Outside the memory.
  kErrNotDone = 0x09,
  kErrFirmware = 0x0A,
  kErrVendor = 0x0B,
  kErrUsbr = 0x0C,
  kErrPor = 0x0D,
  kErrUnknown = 0x0E,
  kErrStalledPkt = 0x0F,  ///< A request the state does not allow.
};

/// The DFU_GETSTATUS answer (DFU 1.1 §6.1.2): bStatus, bwPollTimeout (24 bits, little endian),
/// bState, iString (always 0 here: no status strings).
inline constexpr std::size_t kStatusReplyBytes = 6;
struct StatusReply {
  Status status = Status::kOk;
  std::uint32_t poll_timeout_ms = 0;  ///< How long the host waits before the next GETSTATUS.
  State state = State::kIdle;
};

constexpr void Encode(const StatusReply& r, std::span<std::uint8_t, kStatusReplyBytes> out) {
  out[0] = static_cast<std::uint8_t>(r.status);
  out[1] = static_cast<std::uint8_t>(r.poll_timeout_ms & 0xFF);
  out[2] = static_cast<std::uint8_t>((r.poll_timeout_ms >> 8) & 0xFF);
  out[3] = static_cast<std::uint8_t>((r.poll_timeout_ms >> 16) & 0xFF);
  out[4] = static_cast<std::uint8_t>(r.state);
  out[5] = 0;
}

constexpr StatusReply DecodeStatusReply(std::span<const std::uint8_t, kStatusReplyBytes> in) {
  return StatusReply{static_cast<Status>(in[0]),
                     static_cast<std::uint32_t>(in[1] | (in[2] << 8) | (in[3] << 16)),
                     static_cast<State>(in[4])};
}

/// DfuSe commands (UM0424 §6): the first byte of a DNLOAD to block 0, followed by a 32-bit
/// little-endian address where the command takes one (set address pointer, sector erase).
enum class DfuSeCommand : std::uint8_t {
  kGetCommands = 0x00,
  kSetAddressPointer = 0x21,
  kErase = 0x41,  ///< Alone: mass erase; with an address: the sector that holds it.
  kReadUnprotect = 0x92,
};

/// DfuSe data blocks (UM0424 §6.2): block n holds the bytes at the address pointer +
/// (n - kFirstDataBlock) * wTransferSize; blocks 0 and 1 are for commands.
inline constexpr std::uint16_t kFirstDataBlock = 2;

/// The USB identity of ST's system-memory bootloader in DFU mode (AN3156).
inline constexpr std::uint16_t kStBootloaderVendorId = 0x0483;
inline constexpr std::uint16_t kStBootloaderProductId = 0xDF11;

/// The STM32F405's flash as its bootloader describes it in the DfuSe interface string
/// (RM0090 §3.3: four 16 KiB sectors, one of 64 KiB, seven of 128 KiB).
inline constexpr const char* kStm32f405FlashLayout =
    "@Internal Flash  /0x08000000/04*016Kg,01*064Kg,07*128Kg";

}  // namespace vibid::dfu
