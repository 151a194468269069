// Firmware download through a DfuSe bootloader (DFU 1.1 with ST's extensions, ST AN3156 and
// UM0424): the STM32F405's ROM bootloader on a real board, the emulator's DFU personality over
// USB/IP. Control transfers only, so it runs over any UsbControl.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "vibid/device/usb_control.hpp"
#include "vibid/shared/dfu.hpp"

namespace vibid::device {

/// One erasable sector of the memory a DfuSe interface string describes.
struct DfuSeSector {
  std::uint32_t address = 0;
  std::uint32_t bytes = 0;
};

/// A byte range of the flash.
struct FlashRange {
  std::uint32_t address = 0;
  std::uint32_t bytes = 0;
};

/// The board's calibration slots: sectors 2 and 3 (CAL_SLOTS in the board's linker script).
/// A firmware image never erases or writes them, so the calibration survives a flash.
inline constexpr FlashRange kCalibrationSectors{0x08008000u, 0x8000u};

/// Parses a DfuSe memory layout string, e.g. "@Internal Flash
/// /0x08000000/04*016Kg,01*064Kg,07*128Kg" (name, start address, then COUNT*SIZE[B|K|M]ATTR
/// groups). InputError-free: throws DeviceError naming the string when malformed.
std::vector<DfuSeSector> ParseDfuSeLayout(const std::string& layout);

class DfuSe {
 public:
  /// `interface`: the DFU interface number; `transfer_size`: wTransferSize of its functional
  /// descriptor.
  DfuSe(UsbControl& usb, std::uint8_t interface, std::uint16_t transfer_size);

  /// Finds the DFU interface in the configuration descriptor, its transfer size and the memory
  /// layout of alternate setting 0. Throws DeviceError if the device has no DfuSe interface.
  static DfuSe Open(UsbControl& usb, std::vector<DfuSeSector>& layout);

  dfu::StatusReply GetStatus();
  void ClearStatus();
  void Abort();
  void SetAddress(std::uint32_t address);
  void EraseSector(std::uint32_t address);
  /// Writes `data` (at most transfer_size bytes) at pointer + (block - 2) * transfer_size.
  void Download(std::uint16_t block, std::span<const std::uint8_t> data);
  /// Reads `length` bytes at pointer + (block - 2) * transfer_size.
  std::vector<std::uint8_t> Upload(std::uint16_t block, std::uint16_t length);
  /// Zero-length download from the address pointer: the bootloader manifests and starts the
  /// application.
  void Leave(std::uint32_t address);

  std::uint16_t transfer_size() const { return transfer_size_; }

 private:
  /// Polls GETSTATUS through dfuDNBUSY until the state settles; throws on dfuERROR.
  dfu::StatusReply Settle(const std::string& what);
  void Dnload(std::uint16_t block, std::span<const std::uint8_t> data, const std::string& what);

  UsbControl* usb_;
  std::uint8_t interface_;
  std::uint16_t transfer_size_;
};

using FlashProgress =
    std::function<void(const std::string& phase, std::uint64_t done, std::uint64_t total)>;

/// What flashing an image does: the sectors it erases and the parts of the image it writes.
struct FlashPlan {
  std::vector<std::uint32_t> erase;  ///< sector start addresses, ascending
  std::vector<FlashRange> write;     ///< image parts to download and verify, ascending
};

/// Plans writing `image` at `address` into the flash `layout` describes, leaving every sector
/// that holds a `keep` range alone (neither erased nor written). The image's bytes in such a
/// sector must be 0xFF, the erased value a linker's gap fill gives (`objcopy --gap-fill 0xff`).
/// Throws InputError naming the problem: an empty image, an image outside the flash, or image
/// data in a kept sector (with its first address).
FlashPlan PlanFlash(const std::vector<DfuSeSector>& layout, std::span<const std::uint8_t> image,
                    std::uint32_t address, std::span<const FlashRange> keep);

/// Runs PlanFlash's plan: erases, downloads, reads back and compares byte for byte, then leaves
/// DFU. Throws DeviceError naming the first differing address on a verify failure.
void FlashImage(DfuSe& dfu, const std::vector<DfuSeSector>& layout,
                std::span<const std::uint8_t> image, std::uint32_t address,
                std::span<const FlashRange> keep, const FlashProgress& progress = {});

}  // namespace vibid::device
