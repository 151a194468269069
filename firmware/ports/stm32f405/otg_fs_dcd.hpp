// USB device controller driver for the STM32F405 OTG_FS core in device mode, slave (FIFO) mode:
// the port side of the stack's Dcd contract. Endpoint 0 plus IN/OUT endpoints 1..3.
//
// FIFO RAM plan (320 words): RX 128 words (SETUP + OUT packets for all endpoints), endpoint 0
// TX 16 words (one 64-byte packet), endpoint 1..3 TX 32 words each (two packets).
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "vibid/fw/usb/dcd.hpp"

namespace vibid::fw::stm32 {

/// What the board and its clocks ask of the driver.
struct OtgFsConfig {
  /// HCLK: 168 MHz from the crystal, or 16 MHz on the HSI fallback (the OTG core needs at least
  /// 14.2 MHz). It sets the turnaround time and the forced-mode wait.
  std::uint32_t ahb_hz = 168000000;
  /// The slowest the AHB clock may run (0: ahb_hz). On the HSI fallback the 16 MHz RC oscillator
  /// may run 8 % slow (DS8626), and a TRDT chosen for 16 MHz (0xD) is too short below it
  /// (0xE from 15 MHz, 0xF from 14.2 MHz): TRDT is taken for this clock, the waits for ahb_hz.
  std::uint32_t ahb_min_hz = 0;
  /// VBUS wired to PA9 (pyboard): the core's D+ pull-up then follows VBUS, so a board powered
  /// from elsewhere with the cable out does not show a device to nobody. Otherwise sensing off.
  bool vbus_sensing = false;
};

/// OTG_FS_GUSBCFG TRDT for an AHB clock, full speed (RM0090 §34.16.3 TRDT table; ST's HAL
/// USB_SetTurnaroundTime gives the same ranges): 15 at 14.2 MHz down to 6 from 32 MHz.
constexpr std::uint32_t TurnaroundFor(std::uint32_t ahb_hz) {
  constexpr std::uint32_t kFrom[] = {14200000, 15000000, 16000000, 17200000, 18500000,
                                     20000000, 21800000, 24000000, 27500000, 32000000};
  std::uint32_t trdt = 0xF;
  for (std::uint32_t i = 0; i < sizeof(kFrom) / sizeof(kFrom[0]) && ahb_hz >= kFrom[i]; ++i)
    trdt = 0xF - i;
  return trdt;
}

class OtgFsDcd final : public usb::Dcd {
 public:
  static constexpr unsigned kEndpoints = 4;

  /// Before Init: the clock and VBUS wiring (defaults: 168 MHz, no VBUS sensing).
  void Configure(const OtgFsConfig& config) { config_ = config; }

  Status Init(usb::DcdEvents& events) override;
  void Connect() override;
  void Disconnect() override;
  void SetAddress(std::uint8_t address) override;
  Status EndpointOpen(std::uint8_t ep_addr, usb::EndpointType type,
                      std::uint16_t max_packet) override;
  void EndpointCloseAll() override;
  void EndpointStall(std::uint8_t ep_addr) override;
  void EndpointClearStall(std::uint8_t ep_addr) override;
  Status Transfer(std::uint8_t ep_addr, std::span<std::uint8_t> buffer) override;

  /// The OTG_FS interrupt handler body. Does nothing (and masks the interrupt) before Init.
  void HandleInterrupt();
  /// True while an IN transfer is enabled in the core, i.e. not yet taken by the host.
  bool InTransfersPending() const;

 private:
  struct Endpoint {
    std::span<std::uint8_t> buffer{};
    std::uint16_t done = 0;  ///< Bytes written to the FIFO (IN) or read from it (OUT).
    std::uint16_t max_packet = 64;
    bool busy = false;
  };

  void HandleBusReset();
  void HandleRxFifo();
  void HandleOutEndpoints();
  void HandleInEndpoints();
  void FillTxFifo(unsigned n);
  void ArmSetup();
  void FlushTxFifo(unsigned n);
  void DisableInEndpoint(unsigned n, bool stall);
  void DisableOutEndpoint(unsigned n);

  OtgFsConfig config_{};
  usb::DcdEvents* events_ = nullptr;
  std::array<Endpoint, kEndpoints> in_{};
  std::array<Endpoint, kEndpoints> out_{};
  std::array<std::uint8_t, 8> setup_{};
};

}  // namespace vibid::fw::stm32
