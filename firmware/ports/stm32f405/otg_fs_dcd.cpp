#include "otg_fs_dcd.hpp"

#include <algorithm>

#include "regs/core_m4.hpp"
#include "regs/otg_fs.hpp"
#include "regs/peripherals.hpp"
#include "regs/rcc.hpp"
#include "system.hpp"

namespace vibid::fw::stm32 {
namespace {

constexpr std::uint32_t kRxFifoWords = 128;
constexpr std::uint32_t kEp0TxWords = 16;
constexpr std::uint32_t kEpTxWords = 32;
constexpr std::uint32_t kPollLimit = 200000;

/// A forced mode change takes effect after at most 25 ms (RM0090 §34.16.2, OTG_FS_GUSBCFG FDMOD).
constexpr std::uint32_t kForcedModeMs = 25;
static_assert(TurnaroundFor(168000000) == 6 && TurnaroundFor(16000000) == 0xD &&
              TurnaroundFor(14200000) == 0xF && TurnaroundFor(31999999) == 7);

std::uint16_t PacketCount(std::size_t length, std::uint16_t max_packet) {
  if (length == 0) return 1;
  return static_cast<std::uint16_t>((length + max_packet - 1) / max_packet);
}

}  // namespace

Status OtgFsDcd::Init(usb::DcdEvents& events) {
  // No OTG interrupt until the core is set up; one left pending from before is dropped.
  nvic::Disable(irq::kOtgFs);
  nvic::ClearPending(irq::kOtgFs);
  // PA11 = DM, PA12 = DP, alternate function 10 (RM0090 table 9 / datasheet AF map).
  EnableClock(rcc::kAhb1enr, rcc::kAhb1GpioA);
  gpio::SetAlternate(gpio::kPortA, 11, 10);
  gpio::SetAlternate(gpio::kPortA, 12, 10);
  EnableClock(rcc::kAhb2enr, rcc::kAhb2OtgFs);
  Reg(otg::kGahbcfg) = 0;

  // Core soft reset once the AHB master is idle (RM0090 §34.17.1).
  Reg(otg::kGusbcfg) |= otg::kGusbcfgPhysel;
  if (!WaitFor(otg::kGrstctl, otg::kGrstctlAhbidl, otg::kGrstctlAhbidl, kPollLimit))
    return Status::kUnavailable;
  Reg(otg::kGrstctl) = otg::kGrstctlCsrst;
  if (!WaitFor(otg::kGrstctl, otg::kGrstctlCsrst, 0, kPollLimit)) return Status::kUnavailable;
  // The soft reset cleared DCTL, SDIS with it (RM0090 §34.16.2, OTG_FS_GRSTCTL CSRST: all CSRs but
  // a few PCGCCTL, HCFG and DCFG bits): disconnect again before the transceiver is powered, so the
  // D+ pull-up never shows before Connect (no attach/detach glitch for the host).
  Reg(otg::kDctl) |= otg::kDctlSdis;

  // Transceiver on. With VBUS on PA9 (an input, no pull: MicroPython's pyboard set-up) the core
  // senses it as a B-device and pulls D+ up only while the host powers the bus, as ST's HAL does
  // for vbus_sensing_enable; without it sensing is off (NOVBUSSENS) and D+ follows SDIS alone.
  if (config_.vbus_sensing) {
    gpio::SetMode(gpio::kPortA, 9, gpio::Mode::kInput);
    Reg(otg::kGccfg) = otg::kGccfgPwrdwn | otg::kGccfgVbusbsen;
  } else {
    Reg(otg::kGccfg) = otg::kGccfgPwrdwn | otg::kGccfgNovbussens;
  }
  // Forced device mode, turnaround time for the AHB clock (6 above 32 MHz, 13 at the HSI's
  // 16 MHz); the mode change takes effect after 25 ms, timed by the DWT cycle counter (a loop's
  // duration depends on the flash wait states and the caches).
  Modify(otg::kGusbcfg, otg::kGusbcfgFdmod | otg::kGusbcfgTrdtMask,
         otg::kGusbcfgFdmod |
             Field(TurnaroundFor(config_.ahb_min_hz != 0 ? config_.ahb_min_hz : config_.ahb_hz),
                   otg::kGusbcfgTrdtPos));
  if (!WaitCycles(config_.ahb_hz / 1000 * kForcedModeMs)) return Status::kUnavailable;
  // The mode switch is confirmed, not assumed: CMOD reads 0 in device mode.
  if ((Reg(otg::kGintsts) & otg::kIntCmod) != 0) return Status::kUnavailable;
  Reg(otg::kPcgcctl) = 0;
  Reg(otg::kDcfg) = otg::kDcfgDspdFull;
  Reg(otg::kDctl) |= otg::kDctlSdis;

  Reg(otg::kGrxfsiz) = kRxFifoWords;
  Reg(otg::kDieptxf0) = (kEp0TxWords << 16) | kRxFifoWords;
  for (unsigned n = 1; n < kEndpoints; ++n) {
    const std::uint32_t start = kRxFifoWords + kEp0TxWords + (n - 1) * kEpTxWords;
    Reg(otg::Dieptxf(n)) = (kEpTxWords << 16) | start;
  }
  static_assert(kRxFifoWords + kEp0TxWords + 3 * kEpTxWords <= otg::kFifoWords);
  Reg(otg::kGrstctl) = otg::kGrstctlTxfflsh | otg::kGrstctlTxfnumAll;
  (void)WaitFor(otg::kGrstctl, otg::kGrstctlTxfflsh, 0, kPollLimit);
  Reg(otg::kGrstctl) = otg::kGrstctlRxfflsh;
  (void)WaitFor(otg::kGrstctl, otg::kGrstctlRxfflsh, 0, kPollLimit);

  Reg(otg::kDiepmsk) = otg::kEpIntXfrc;
  Reg(otg::kDoepmsk) = otg::kEpIntXfrc | otg::kEpIntStup;
  Reg(otg::kGintsts) = 0xFFFFFFFF;
  Reg(otg::kGintmsk) = otg::kIntRxflvl | otg::kIntUsbsusp | otg::kIntUsbrst | otg::kIntEnumdne |
                       otg::kIntIepint | otg::kIntOepint | otg::kIntWkupint;
  events_ = &events;
  Reg(otg::kGahbcfg) = otg::kGahbcfgGint;
  nvic::ClearPending(irq::kOtgFs);
  nvic::SetPriority(irq::kOtgFs, 6);
  nvic::Enable(irq::kOtgFs);
  return Status::kOk;
}

void OtgFsDcd::Connect() { Reg(otg::kDctl) &= ~otg::kDctlSdis; }
void OtgFsDcd::Disconnect() { Reg(otg::kDctl) |= otg::kDctlSdis; }

void OtgFsDcd::SetAddress(std::uint8_t address) {
  // The core answers the status stage with the old address, so the new one is set now.
  Modify(otg::kDcfg, otg::kDcfgDadMask, Field(address, otg::kDcfgDadPos));
}

Status OtgFsDcd::EndpointOpen(std::uint8_t ep_addr, usb::EndpointType type,
                              std::uint16_t max_packet) {
  const unsigned n = usb::EpNumber(ep_addr);
  if (n == 0 || n >= kEndpoints || max_packet > 64) return Status::kResourceExhausted;
  CriticalSection lock;
  const std::uint32_t ctl = (max_packet & otg::kEpctlMpsizMask) | otg::kEpctlUsbaep |
                            otg::kEpctlSd0pid |
                            Field(static_cast<std::uint32_t>(type), otg::kEpctlEptypPos);
  if (usb::IsIn(ep_addr)) {
    in_[n] = Endpoint{{}, 0, max_packet, false};
    Reg(otg::Diepctl(n)) = ctl | Field(n, otg::kEpctlTxfnumPos) | otg::kEpctlSnak;
    Reg(otg::kDaintmsk) |= Bit(n);
  } else {
    out_[n] = Endpoint{{}, 0, max_packet, false};
    Reg(otg::Doepctl(n)) = ctl | otg::kEpctlSnak;
    Reg(otg::kDaintmsk) |= Bit(16 + n);
  }
  return Status::kOk;
}

void OtgFsDcd::EndpointCloseAll() {
  CriticalSection lock;
  for (unsigned n = 1; n < kEndpoints; ++n) {
    DisableInEndpoint(n, false);
    DisableOutEndpoint(n);
    Reg(otg::Diepctl(n)) &= ~otg::kEpctlUsbaep;
    Reg(otg::Doepctl(n)) &= ~otg::kEpctlUsbaep;
    in_[n] = Endpoint{};
    out_[n] = Endpoint{};
  }
  Reg(otg::kDaintmsk) = Bit(0) | Bit(16);
  Reg(otg::kDiepempmsk) = 0;
}

void OtgFsDcd::EndpointStall(std::uint8_t ep_addr) {
  const unsigned n = usb::EpNumber(ep_addr);
  if (n >= kEndpoints) return;
  CriticalSection lock;
  if (usb::IsIn(ep_addr)) {
    DisableInEndpoint(n, true);
  } else {
    Reg(otg::Doepctl(n)) |= otg::kEpctlStall;
    out_[n].busy = false;
    if (n == 0) {
      // A control stall ends the data stage: whatever EP0 IN still holds goes too.
      DisableInEndpoint(0, true);
      ArmSetup();
    }
  }
}

void OtgFsDcd::EndpointClearStall(std::uint8_t ep_addr) {
  const unsigned n = usb::EpNumber(ep_addr);
  if (n == 0 || n >= kEndpoints) return;
  CriticalSection lock;
  // Clearing the halt resets the data toggle to DATA0 (USB 2.0 §9.4.5).
  const Address ctl = usb::IsIn(ep_addr) ? otg::Diepctl(n) : otg::Doepctl(n);
  Reg(ctl) = (Reg(ctl) & ~otg::kEpctlStall) | otg::kEpctlSd0pid;
}

Status OtgFsDcd::Transfer(std::uint8_t ep_addr, std::span<std::uint8_t> buffer) {
  const unsigned n = usb::EpNumber(ep_addr);
  if (n >= kEndpoints) return Status::kInvalidArgument;
  CriticalSection lock;
  if (usb::IsIn(ep_addr)) {
    Endpoint& ep = in_[n];
    if (ep.busy) return Status::kUnavailable;
    ep = Endpoint{buffer, 0, ep.max_packet, true};
    const std::uint16_t packets = PacketCount(buffer.size(), ep.max_packet);
    Reg(otg::Dieptsiz(n)) =
        Field(packets, otg::kTsizPktcntPos) | static_cast<std::uint32_t>(buffer.size());
    Reg(otg::Diepctl(n)) |= otg::kEpctlCnak | otg::kEpctlEpena;
    if (!buffer.empty()) Reg(otg::kDiepempmsk) |= Bit(n);
  } else {
    Endpoint& ep = out_[n];
    if (ep.busy) return Status::kUnavailable;
    ep = Endpoint{buffer, 0, ep.max_packet, true};
    const std::uint16_t packets = PacketCount(buffer.size(), ep.max_packet);
    std::uint32_t tsiz =
        Field(packets, otg::kTsizPktcntPos) + static_cast<std::uint32_t>(packets) * ep.max_packet;
    if (n == 0) tsiz |= otg::kDoeptsiz0Stupcnt3;
    Reg(otg::Doeptsiz(n)) = tsiz;
    Reg(otg::Doepctl(n)) |= otg::kEpctlCnak | otg::kEpctlEpena;
  }
  return Status::kOk;
}

void OtgFsDcd::ArmSetup() {
  // Up to three back-to-back SETUP packets, 8 bytes each (RM0090 §34.17.6 OUT endpoint 0).
  Reg(otg::Doeptsiz(0)) = otg::kDoeptsiz0Stupcnt3 | Field(1, otg::kTsizPktcntPos) | (3 * 8);
}

bool OtgFsDcd::InTransfersPending() const {
  for (unsigned n = 0; n < kEndpoints; ++n) {
    if ((Reg(otg::Diepctl(n)) & otg::kEpctlEpena) != 0) return true;
  }
  return false;
}

void OtgFsDcd::FlushTxFifo(unsigned n) {
  Reg(otg::kGrstctl) = otg::kGrstctlTxfflsh | Field(n, otg::kGrstctlTxfnumPos);
  (void)WaitFor(otg::kGrstctl, otg::kGrstctlTxfflsh, 0, kPollLimit);
}

void OtgFsDcd::DisableInEndpoint(unsigned n, bool stall) {
  // TinyUSB dwc2 order (RM0090 §34.17.7 "Disabling an IN endpoint"): an endpoint that is not
  // enabled is only NAKed (and stalled); an enabled one is NAKed, and once the NAK is effective
  // disabled, waiting for EPDISD. Then its TX FIFO is flushed so no stale packet goes out after
  // the next SETUP. Every wait is bounded.
  const std::uint32_t stall_bit = stall ? otg::kEpctlStall : 0;
  if ((Reg(otg::Diepctl(n)) & otg::kEpctlEpena) == 0) {
    Reg(otg::Diepctl(n)) |= otg::kEpctlSnak | stall_bit;
  } else {
    Reg(otg::Diepctl(n)) |= otg::kEpctlSnak;
    (void)WaitFor(otg::Diepint(n), otg::kEpIntInepne, otg::kEpIntInepne, kPollLimit);
    Reg(otg::Diepctl(n)) |= otg::kEpctlEpdis | otg::kEpctlSnak | stall_bit;
    (void)WaitFor(otg::Diepint(n), otg::kEpIntEpdisd, otg::kEpIntEpdisd, kPollLimit);
    Reg(otg::Diepint(n)) = otg::kEpIntEpdisd | otg::kEpIntInepne;
  }
  FlushTxFifo(n);
  Reg(otg::kDiepempmsk) &= ~Bit(n);
  in_[n].busy = false;
}

void OtgFsDcd::DisableOutEndpoint(unsigned n) {
  // RM0090 §34.17.6 "Disabling an OUT endpoint": global OUT NAK first, then EPDIS with SNAK,
  // wait for EPDISD, then clear the global OUT NAK. Every wait is bounded.
  if ((Reg(otg::Doepctl(n)) & otg::kEpctlEpena) == 0) {
    out_[n].busy = false;
    return;
  }
  Reg(otg::kDctl) |= otg::kDctlSgonak;
  // The core queues a "global OUT NAK" entry behind what the RX FIFO holds and sets GONAKEFF
  // only once it has been popped (RM0090 "Setting the global OUT NAK"): the FIFO is drained
  // here, since the interrupt that normally does it may be masked.
  for (std::uint32_t i = 0; i < kPollLimit; ++i) {
    const std::uint32_t status = Reg(otg::kGintsts);
    if ((status & otg::kIntGonakeff) != 0) break;
    if ((status & otg::kIntRxflvl) != 0) HandleRxFifo();
  }
  Reg(otg::Doepctl(n)) |= otg::kEpctlEpdis | otg::kEpctlSnak;
  (void)WaitFor(otg::Doepint(n), otg::kEpIntEpdisd, otg::kEpIntEpdisd, kPollLimit);
  Reg(otg::Doepint(n)) = otg::kEpIntEpdisd;
  Reg(otg::kDctl) |= otg::kDctlCgonak;
  out_[n].busy = false;
}

void OtgFsDcd::HandleInterrupt() {
  if (events_ == nullptr) {
    // Not initialised: nothing may run; the interrupt stays off until Init enables it.
    nvic::Disable(irq::kOtgFs);
    return;
  }
  const std::uint32_t status = Reg(otg::kGintsts) & Reg(otg::kGintmsk);
  if ((status & otg::kIntUsbrst) != 0) {
    Reg(otg::kGintsts) = otg::kIntUsbrst;
    HandleBusReset();
  }
  if ((status & otg::kIntEnumdne) != 0) {
    Reg(otg::kGintsts) = otg::kIntEnumdne;
    // Endpoint 0 max packet 64 (MPSIZ 00) once the speed is known.
    Reg(otg::Diepctl(0)) &= ~0x3U;
    Reg(otg::kDctl) |= otg::kDctlCginak;
  }
  if ((status & otg::kIntRxflvl) != 0) HandleRxFifo();
  if ((status & otg::kIntOepint) != 0) HandleOutEndpoints();
  if ((status & otg::kIntIepint) != 0) HandleInEndpoints();
  if ((status & otg::kIntUsbsusp) != 0) {
    Reg(otg::kGintsts) = otg::kIntUsbsusp;
    // 3 ms of idle bus: the host suspended it (USB 2.0 §7.1.7.6), and the device may draw only
    // 2.5 mA from VBUS (§7.2.3). The PHY clock stops once DSTS confirms it (RM0090's device
    // suspend steps: SUSPSTS, then PCGCCTL STPPCLK, as ST's HAL does with low-power enabled); the
    // resume or a bus reset is still detected and raises WKUPINT.
    if ((Reg(otg::kDsts) & otg::kDstsSuspsts) != 0) Reg(otg::kPcgcctl) |= otg::kPcgcctlStppclk;
    events_->OnSuspend();
  }
  if ((status & otg::kIntWkupint) != 0) {
    // The PHY clock runs again before anything else touches the core.
    Reg(otg::kPcgcctl) &= ~otg::kPcgcctlStppclk;
    Reg(otg::kGintsts) = otg::kIntWkupint;
    events_->OnResume();
  }
}

void OtgFsDcd::HandleBusReset() {
  // A reset out of suspend: the PHY clock must run (RM0090: STPPCLK cleared on any exit).
  Reg(otg::kPcgcctl) &= ~otg::kPcgcctlStppclk;
  Modify(otg::kDcfg, otg::kDcfgDadMask, 0);
  for (unsigned n = 0; n < kEndpoints; ++n) {
    Reg(otg::Doepctl(n)) |= otg::kEpctlSnak;
    Reg(otg::Diepint(n)) = 0xFF;
    Reg(otg::Doepint(n)) = 0xFF;
    in_[n] = Endpoint{};
    out_[n] = Endpoint{};
  }
  Reg(otg::kDaintmsk) = Bit(0) | Bit(16);
  Reg(otg::kDiepempmsk) = 0;
  Reg(otg::kGrstctl) = otg::kGrstctlTxfflsh | otg::kGrstctlTxfnumAll;
  (void)WaitFor(otg::kGrstctl, otg::kGrstctlTxfflsh, 0, kPollLimit);
  ArmSetup();
  events_->OnBusReset();
}

void OtgFsDcd::HandleRxFifo() {
  const std::uint32_t rxsts = Reg(otg::kGrxstsp);
  const unsigned n = rxsts & 0xF;
  const std::uint32_t count = (rxsts >> 4) & 0x7FF;
  const std::uint32_t packet_status = (rxsts >> 17) & 0xF;
  const std::uint32_t words = (count + 3) / 4;
  if (packet_status == otg::kRxstsPktSetupData) {
    for (std::uint32_t w = 0; w < words; ++w) {
      const std::uint32_t v = Reg(otg::Fifo(0));
      for (std::uint32_t b = 0; b < 4 && 4 * w + b < setup_.size(); ++b) {
        setup_[4 * w + b] = static_cast<std::uint8_t>(v >> (8 * b));
      }
    }
    return;
  }
  if (packet_status == otg::kRxstsPktOutData && n < kEndpoints) {
    Endpoint& ep = out_[n];
    for (std::uint32_t w = 0; w < words; ++w) {
      const std::uint32_t v = Reg(otg::Fifo(0));
      for (std::uint32_t b = 0; b < 4 && 4 * w + b < count; ++b) {
        // Bytes beyond the posted buffer are read out of the FIFO and dropped.
        if (ep.done < ep.buffer.size())
          ep.buffer[ep.done++] = static_cast<std::uint8_t>(v >> (8 * b));
      }
    }
  }
}

void OtgFsDcd::HandleOutEndpoints() {
  const std::uint32_t pending = Reg(otg::kDaint) >> 16;
  for (unsigned n = 0; n < kEndpoints; ++n) {
    if ((pending & Bit(n)) == 0) continue;
    const std::uint32_t flags = Reg(otg::Doepint(n));
    Reg(otg::Doepint(n)) = flags;
    if ((flags & otg::kEpIntStup) != 0 && n == 0) {
      out_[0] = Endpoint{};
      // A new SETUP aborts the previous control transfer: its IN data must not follow.
      DisableInEndpoint(0, false);
      ArmSetup();
      events_->OnSetupReceived(setup_);
    }
    if ((flags & otg::kEpIntXfrc) != 0 && out_[n].busy) {
      out_[n].busy = false;
      if (n == 0) ArmSetup();
      events_->OnTransferComplete(static_cast<std::uint8_t>(n), out_[n].done);
    }
  }
}

void OtgFsDcd::HandleInEndpoints() {
  const std::uint32_t pending = Reg(otg::kDaint) & 0xFFFF;
  const std::uint32_t empty_mask = Reg(otg::kDiepempmsk);
  for (unsigned n = 0; n < kEndpoints; ++n) {
    if ((pending & Bit(n)) == 0) continue;
    const std::uint32_t flags = Reg(otg::Diepint(n));
    if ((flags & otg::kEpIntXfrc) != 0) {
      Reg(otg::Diepint(n)) = otg::kEpIntXfrc;
      if (in_[n].busy) {
        in_[n].busy = false;
        events_->OnTransferComplete(static_cast<std::uint8_t>(0x80 | n),
                                    static_cast<std::uint16_t>(in_[n].buffer.size()));
      }
    }
    if ((flags & otg::kEpIntTxfe) != 0 && (empty_mask & Bit(n)) != 0) FillTxFifo(n);
  }
}

void OtgFsDcd::FillTxFifo(unsigned n) {
  Endpoint& ep = in_[n];
  while (ep.done < ep.buffer.size()) {
    const std::size_t remaining = ep.buffer.size() - ep.done;
    const std::size_t packet = std::min<std::size_t>(remaining, ep.max_packet);
    const std::uint32_t words = static_cast<std::uint32_t>((packet + 3) / 4);
    if ((Reg(otg::Dtxfsts(n)) & 0xFFFF) < words) return;  // Wait for the next TXFE.
    for (std::uint32_t w = 0; w < words; ++w) {
      std::uint32_t v = 0;
      for (std::uint32_t b = 0; b < 4; ++b) {
        const std::size_t i = ep.done + 4 * w + b;
        if (i < ep.done + packet) v |= static_cast<std::uint32_t>(ep.buffer[i]) << (8 * b);
      }
      Reg(otg::Fifo(n)) = v;
    }
    ep.done = static_cast<std::uint16_t>(ep.done + packet);
  }
  Reg(otg::kDiepempmsk) &= ~Bit(n);
}

}  // namespace vibid::fw::stm32
