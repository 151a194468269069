// The emulated DfuSe bootloader: what the STM32F405's ROM bootloader shows over USB after the
// application entered DFU (ST AN3156, UM0424; DFU 1.1 with ST's DfuSe extensions). It writes the
// emulator's flash image. One interface, control transfers only:
//
//   DNLOAD block 0   commands: 0x21 + u32 address = set address pointer, 0x41 = mass erase,
//                    0x41 + u32 address = erase the sector holding it, 0x92 = read unprotect
//   DNLOAD block n≥2 data for pointer + (n − 2) · 2048 (wTransferSize)
//   UPLOAD block 0   the supported commands {0x00, 0x21, 0x41, 0x92}
//   UPLOAD block n≥2 flash from pointer + (n − 2) · 2048
//   GETSTATUS        runs a downloaded block: dfuDNBUSY (with its poll time), then dfuDNLOAD-IDLE;
//                    in dfuMANIFEST-SYNC (a zero-length DNLOAD) it answers dfuMANIFEST and the
//                    bootloader leaves: the emulator restarts the application.
//   GETSTATE, CLRSTATUS (from dfuERROR), ABORT (to dfuIDLE)
//
// Errors follow DFU 1.1: the state becomes dfuERROR with bStatus errADDRESS (outside the flash),
// errVERIFY (programming over bytes that were not erased), errTARGET (unknown command);
// a request not allowed in the current state stalls (errSTALLEDPKT).
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "exported_device.hpp"
#include "flash_image.hpp"
#include "vibid/shared/dfu.hpp"

namespace vibid::emu {

class DfuSeBootloader final : public ExportedDevice {
 public:
  static constexpr std::uint16_t kTransferSize = 2048;

  /// `record` is the base identity (busid, bus/dev numbers); the ids become ST's bootloader's.
  DfuSeBootloader(FlashImage& flash, usbip::UsbDevice record, std::string serial);

  usbip::UsbDevice Describe() const override;
  void Attach(UrbSink& sink) override;
  void Detach() override { sink_ = nullptr; }
  void Submit(Urb urb) override;
  bool Unlink(std::uint32_t) override { return false; }  // control URBs complete at once
  void Service() override {}

  /// True once a manifestation completed: the emulator restarts the application.
  bool leave_requested() const { return leave_; }
  dfu::State state() const { return state_; }

 private:
  UrbResult Control(const std::array<std::uint8_t, 8>& setup, const std::vector<std::uint8_t>& out,
                    std::uint32_t length);
  UrbResult Standard(std::uint8_t request, std::uint16_t value, std::uint16_t length);
  UrbResult Dfu(std::uint8_t request, std::uint16_t value, const std::vector<std::uint8_t>& out,
                std::uint16_t length);
  UrbResult GetStatus();
  void ExecuteDownload();
  UrbResult StallAndError();
  void Fail(dfu::Status status);
  std::vector<std::uint8_t> StringDescriptor(std::uint8_t index) const;

  FlashImage& flash_;
  usbip::UsbDevice record_;
  std::string serial_;
  UrbSink* sink_ = nullptr;
  dfu::State state_ = dfu::State::kIdle;
  dfu::Status status_ = dfu::Status::kOk;
  bool download_done_ = false;
  std::uint32_t poll_timeout_ms_ = 0;
  std::uint32_t address_ = FlashImage::kBase;
  std::uint16_t block_ = 0;
  std::vector<std::uint8_t> block_data_;
  std::uint8_t configuration_ = 0;
  bool leave_ = false;
};

}  // namespace vibid::emu
