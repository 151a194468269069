// OTG_FS driver on the fake register file: interrupt hygiene at Init, device mode confirmed,
// EP0 IN disabled and its FIFO flushed on SETUP and on stall (TinyUSB dwc2), the RM0090 OUT
// endpoint disable sequence, and a DSB after the clock enable (ES0182 §2.1.13).
#include <vector>

#include "otg_fs_dcd.hpp"
#include "port_test_fixture.hpp"
#include "regs/core_m4.hpp"
#include "regs/otg_fs.hpp"
#include "regs/peripherals.hpp"
#include "regs/rcc.hpp"

namespace vibid::fw::stm32::test {
namespace {

// OTG_FS is IRQ 67: NVIC word 2, bit 3.
constexpr Address kIser2 = 0xE000E108;
constexpr Address kIcer2 = 0xE000E188;
constexpr Address kIcpr2 = 0xE000E288;
constexpr std::uint32_t kOtgBit = Bit(3);

class Events final : public usb::DcdEvents {
 public:
  void OnBusReset() override { calls.push_back("reset"); }
  void OnSetupReceived(std::span<const std::uint8_t, 8>) override {
    calls.push_back("setup");
    log_at_setup = FakeRegisters::Get().log().size();
  }
  void OnTransferComplete(std::uint8_t, std::uint16_t) override { calls.push_back("xfer"); }
  void OnSuspend() override { calls.push_back("suspend"); }
  void OnResume() override { calls.push_back("resume"); }
  std::vector<const char*> calls;
  std::size_t log_at_setup = 0;
};

class OtgTest : public PortTest {
 protected:
  void SetUp() override {
    PortTest::SetUp();
    ModelCore();
  }
  /// The core's self-clearing reset and flush bits, EPDIS completing into EPDISD, and the
  /// global OUT NAK taking effect.
  static void ModelCore() {
    // The DWT cycle counter runs: each read is a millisecond (168 000 cycles) later.
    regs().OnRead(dwt::kCyccnt, [](std::uint32_t held) {
      FakeRegisters::Get().Poke(dwt::kCyccnt, held + 168000);
      return held + 168000;
    });
    regs().OnRead(otg::kGrstctl, [](std::uint32_t held) { return held | otg::kGrstctlAhbidl; });
    regs().OnWrite(otg::kGrstctl, [](std::uint32_t, std::uint32_t w) {
      return w & ~(otg::kGrstctlCsrst | otg::kGrstctlTxfflsh | otg::kGrstctlRxfflsh);
    });
    for (unsigned n = 0; n < OtgFsDcd::kEndpoints; ++n) {
      for (const bool in : {true, false}) {
        const Address ctl = in ? otg::Diepctl(n) : otg::Doepctl(n);
        const Address intr = in ? otg::Diepint(n) : otg::Doepint(n);
        regs().OnWrite(ctl, [intr, in](std::uint32_t, std::uint32_t w) {
          if (in && (w & otg::kEpctlSnak) != 0) {
            FakeRegisters::Get().Poke(intr, FakeRegisters::Get().Peek(intr) | otg::kEpIntInepne);
            w &= ~otg::kEpctlSnak;
          }
          if ((w & otg::kEpctlEpdis) != 0) {
            FakeRegisters::Get().Poke(intr, FakeRegisters::Get().Peek(intr) | otg::kEpIntEpdisd);
            w &= ~(otg::kEpctlEpdis | otg::kEpctlEpena);
          }
          return w;
        });
        // Write-1-to-clear interrupt flags.
        regs().OnWrite(intr, [](std::uint32_t held, std::uint32_t w) { return held & ~w; });
      }
    }
    // GINTSTS flags are write-1-to-clear.
    regs().OnWrite(otg::kGintsts, [](std::uint32_t held, std::uint32_t w) { return held & ~w; });
    // SGONAK queues the "global OUT NAK effective" entry (PKTSTS 0001) in the RX FIFO;
    // GONAKEFF is set once it has been popped; CGONAK ends the mode.
    regs().OnWrite(otg::kDctl, [](std::uint32_t held, std::uint32_t w) {
      FakeRegisters& r = FakeRegisters::Get();
      if ((w & otg::kDctlSgonak) != 0 && (held & otg::kDctlSgonak) == 0) {
        r.Poke(otg::kGintsts, r.Peek(otg::kGintsts) | otg::kIntRxflvl);
        r.Poke(otg::kGrxstsp, 1U << 17);
      }
      if ((w & otg::kDctlCgonak) != 0) {
        w &= ~(otg::kDctlSgonak | otg::kDctlCgonak);
        r.Poke(otg::kGintsts, r.Peek(otg::kGintsts) & ~otg::kIntGonakeff);
      }
      return w;
    });
    regs().OnRead(otg::kGrxstsp, [](std::uint32_t held) {
      FakeRegisters& r = FakeRegisters::Get();
      if (held == (1U << 17)) {
        r.Poke(otg::kGintsts, (r.Peek(otg::kGintsts) & ~otg::kIntRxflvl) | otg::kIntGonakeff);
        r.Poke(otg::kGrxstsp, 0);
      }
      return held;
    });
  }
  OtgFsDcd dcd_;
  Events events_;
};

TEST_F(OtgTest, InitMasksAndClearsTheInterruptUntilTheCoreIsReady) {
  ASSERT_EQ(dcd_.Init(events_), Status::kOk);
  const auto& log = regs().log();
  const std::size_t masked = regs().FindWrite(kIcer2, kOtgBit);
  const std::size_t cleared = regs().FindWrite(kIcpr2, kOtgBit);
  ASSERT_EQ(masked, 0U);  // the very first access
  ASSERT_EQ(cleared, 1U);
  // A DSB right after the OTG clock enable write.
  const std::size_t clock = regs().FindWriteWithBits(rcc::kAhb2enr, rcc::kAhb2OtgFs);
  ASSERT_NE(clock, kNone);
  EXPECT_EQ(log[clock + 1].kind, Access::Kind::kCpu);
  EXPECT_EQ(log[clock + 1].op, fake::CpuOp::kDsb);
  // Core interrupts cleared, global enable, pending cleared again, then the NVIC enable last.
  const std::size_t sts = regs().FindWrite(otg::kGintsts, 0xFFFFFFFF);
  const std::size_t gint = regs().FindWrite(otg::kGahbcfg, otg::kGahbcfgGint, sts);
  const std::size_t cleared_again = regs().FindWrite(kIcpr2, kOtgBit, gint);
  const std::size_t enabled = regs().FindWrite(kIser2, kOtgBit, cleared_again);
  ASSERT_NE(enabled, kNone);
  EXPECT_EQ(regs().FindWrite(kIser2, kOtgBit), enabled);  // never enabled earlier
}

TEST_F(OtgTest, InitDisconnectsRightAfterTheCoreResetAndTimesTheModeChange) {
  ASSERT_EQ(dcd_.Init(events_), Status::kOk);
  const std::size_t reset = regs().FindWrite(otg::kGrstctl, otg::kGrstctlCsrst);
  const std::size_t sdis = regs().FindWriteWithBits(otg::kDctl, otg::kDctlSdis, reset);
  const std::size_t transceiver = regs().FindWriteWithBits(otg::kGccfg, otg::kGccfgPwrdwn);
  const std::size_t device_mode = regs().FindWriteWithBits(otg::kGusbcfg, otg::kGusbcfgFdmod);
  ASSERT_NE(reset, kNone);
  ASSERT_NE(sdis, kNone);
  // SDIS lands before the transceiver is powered and before device mode is forced: the pull-up
  // cannot appear before Connect.
  EXPECT_LT(sdis, transceiver);
  EXPECT_LT(sdis, device_mode);
  // The 25 ms forced-mode wait (RM0090 OTG_FS_GUSBCFG FDMOD) by the DWT: 168 000 cycles per fake
  // read, so at least 25 reads of CYCCNT between FDMOD and the CMOD check.
  std::size_t cycle_reads = 0;
  const std::size_t cmod_check = regs().log().size();
  for (std::size_t i = device_mode; i < cmod_check; ++i) {
    const Access& a = regs().log()[i];
    cycle_reads += a.kind == Access::Kind::kRead && a.address == dwt::kCyccnt;
  }
  EXPECT_GE(cycle_reads, 26U);  // the start, then 25 ms
  EXPECT_LE(cycle_reads, 27U);
}

TEST_F(OtgTest, WithoutVbusWiredSensingIsOffAndTheTurnaroundIsFor168MHz) {
  ASSERT_EQ(dcd_.Init(events_), Status::kOk);
  // OTG_FS_GCCFG (RM0090 §34.16.1): PWRDWN 16, NOVBUSSENS 21, VBUSBSEN 19 clear.
  EXPECT_EQ(regs().Peek(otg::kGccfg), Bit(16) | Bit(21));
  // GUSBCFG TRDT (13:10) = 6 above 32 MHz.
  EXPECT_EQ((regs().Peek(otg::kGusbcfg) >> 10) & 0xF, 6U);
}

TEST_F(OtgTest, VbusOnPa9GatesThePullUp) {
  // pyboard v1.1: VBUS to PA9. PA9 an input (MODER 19:18 = 00), B-device sensing on (VBUSBSEN,
  // bit 19), NOVBUSSENS (bit 21) clear: the core pulls D+ up only with VBUS present.
  regs().Poke(gpio::kPortA + gpio::kModer, 0x3U << 18);
  dcd_.Configure(OtgFsConfig{.ahb_hz = 168000000, .vbus_sensing = true});
  ASSERT_EQ(dcd_.Init(events_), Status::kOk);
  EXPECT_EQ(regs().Peek(otg::kGccfg), Bit(16) | Bit(19));
  EXPECT_EQ(regs().Peek(gpio::kPortA + gpio::kModer) & (0x3U << 18), 0U);
  EXPECT_LT(regs().FindWrite(gpio::kPortA + gpio::kModer, regs().Peek(gpio::kPortA + gpio::kModer)),
            regs().FindWriteWithBits(otg::kGccfg, Bit(19)));
}

TEST_F(OtgTest, OnTheHsiTheTurnaroundAndTheModeWaitFollowTheClock) {
  // 16 MHz HCLK: TRDT 0xD (16-17.2 MHz; RM0090's TRDT table, ST's HAL alike); the 25 ms wait
  // is 400 000 cycles, i.e. three reads of the fake's 168 000-cycle steps.
  // The HSI may run 8 % slow over temperature (DS8626: 14.72 MHz), where 0xD is too short: the
  // board image states that slowest clock and gets 0xF (14.2-15 MHz), the 25 ms wait still
  // counted at 16 MHz.
  dcd_.Configure(OtgFsConfig{.ahb_hz = 16000000, .ahb_min_hz = 14720000, .vbus_sensing = false});
  ASSERT_EQ(dcd_.Init(events_), Status::kOk);
  EXPECT_EQ((regs().Peek(otg::kGusbcfg) >> 10) & 0xF, 0xFU);
  const std::size_t device_mode = regs().FindWriteWithBits(otg::kGusbcfg, otg::kGusbcfgFdmod);
  std::size_t cycle_reads = 0;
  for (std::size_t i = device_mode; i < regs().log().size(); ++i) {
    const Access& a = regs().log()[i];
    if (a.kind == Access::Kind::kWrite && a.address == otg::kPcgcctl) break;
    cycle_reads += a.kind == Access::Kind::kRead && a.address == dwt::kCyccnt;
  }
  EXPECT_GE(cycle_reads, 3U);
  EXPECT_LE(cycle_reads, 4U);
  EXPECT_EQ(TurnaroundFor(14200000), 0xFU);
  EXPECT_EQ(TurnaroundFor(15999999), 0xEU);  // below 16 MHz: 0xE
  EXPECT_EQ(TurnaroundFor(16000000), 0xDU);
  EXPECT_EQ(TurnaroundFor(24000000), 0x8U);
  EXPECT_EQ(TurnaroundFor(27499999), 0x8U);
  EXPECT_EQ(TurnaroundFor(32000000), 0x6U);
}

TEST_F(OtgTest, InitRefusesACoreWithoutACycleCounter) {
  regs().OnRead(dwt::kCyccnt, [](std::uint32_t held) { return held; });
  EXPECT_EQ(dcd_.Init(events_), Status::kUnavailable);
  EXPECT_EQ(regs().FindWrite(kIser2, kOtgBit), kNone);
}

TEST_F(OtgTest, InitRefusesACoreThatStaysInHostMode) {
  regs().Poke(otg::kGintsts, otg::kIntCmod);
  EXPECT_EQ(dcd_.Init(events_), Status::kUnavailable);
  EXPECT_EQ(regs().FindWrite(kIser2, kOtgBit), kNone);
}

TEST_F(OtgTest, InterruptBeforeInitTouchesNothing) {
  regs().Poke(otg::kGintsts, otg::kIntUsbrst | otg::kIntEnumdne);
  regs().Poke(otg::kGintmsk, 0xFFFFFFFF);
  dcd_.HandleInterrupt();
  ASSERT_EQ(regs().WritesTo(kIcer2), std::vector<std::uint32_t>{kOtgBit});
  for (const Access& a : regs().log()) {
    EXPECT_FALSE(a.kind == Access::Kind::kWrite && a.address >= otg::kBase &&
                 a.address < otg::kBase + 0x40000);
  }
  EXPECT_TRUE(events_.calls.empty());
}

TEST_F(OtgTest, ASuspendedBusStopsThePhyClockUntilTheHostResumes) {
  ASSERT_EQ(dcd_.Init(events_), Status::kOk);
  // USBSUSP (GINTSTS bit 11) with DSTS SUSPSTS (bit 0): PCGCCTL (0x50000E00) STPPCLK (bit 0) set,
  // the flag cleared, the stack told (RM0090 §34.16.5; USB 2.0 §7.2.3: 2.5 mA while suspended).
  regs().Poke(otg::kDsts, Bit(0));
  regs().Poke(otg::kGintsts, Bit(11));
  std::size_t before = regs().log().size();
  dcd_.HandleInterrupt();
  EXPECT_EQ(regs().Peek(0x50000E00) & Bit(0), Bit(0));
  EXPECT_NE(regs().FindWriteWithBits(0x50000E00, Bit(0), before), kNone);
  EXPECT_EQ(regs().Peek(otg::kGintsts) & Bit(11), 0U);
  EXPECT_EQ(events_.calls, std::vector<const char*>{"suspend"});
  // WKUPINT (bit 31): STPPCLK cleared before the flag and the stack's resume.
  regs().Poke(otg::kDsts, 0);
  regs().Poke(otg::kGintsts, Bit(31));
  before = regs().log().size();
  dcd_.HandleInterrupt();
  const std::size_t clock = regs().FindWrite(0x50000E00, 0, before);
  const std::size_t flag = regs().FindWrite(otg::kGintsts, Bit(31), before);
  ASSERT_NE(clock, kNone);
  EXPECT_LT(clock, flag);
  EXPECT_EQ(events_.calls, (std::vector<const char*>{"suspend", "resume"}));
  // A USBSUSP the core does not confirm (SUSPSTS 0: the bus came back already) leaves the clock.
  regs().Poke(otg::kGintsts, Bit(11));
  dcd_.HandleInterrupt();
  EXPECT_EQ(regs().Peek(0x50000E00), 0U);
  // A bus reset out of suspend runs the PHY clock again too.
  regs().Poke(0x50000E00, Bit(0));
  regs().Poke(otg::kGintsts, otg::kIntUsbrst);
  dcd_.HandleInterrupt();
  EXPECT_EQ(regs().Peek(0x50000E00), 0U);
}

TEST_F(OtgTest, NewSetupDisablesEp0InAndFlushesItsFifoFirst) {
  ASSERT_EQ(dcd_.Init(events_), Status::kOk);
  // A control read still in flight on EP0 IN when the host sends a new SETUP.
  regs().Poke(otg::Diepctl(0), otg::kEpctlEpena);
  const std::size_t before = regs().log().size();
  regs().Poke(otg::kGintsts, otg::kIntOepint);
  regs().Poke(otg::kDaint, Bit(16));
  regs().Poke(otg::Doepint(0), otg::kEpIntStup);
  dcd_.HandleInterrupt();
  ASSERT_EQ(events_.calls, std::vector<const char*>{"setup"});
  // NAK first, EPDIS only once the NAK is effective (INEPNE), then EPDISD acknowledged.
  const std::size_t nak = regs().FindWriteWithBits(otg::Diepctl(0), otg::kEpctlSnak, before);
  const std::size_t disable =
      regs().FindWriteWithBits(otg::Diepctl(0), otg::kEpctlEpdis | otg::kEpctlSnak, before);
  ASSERT_NE(nak, kNone);
  EXPECT_LT(nak, disable);
  EXPECT_EQ(regs().log()[nak].value & otg::kEpctlEpdis, 0U);
  const std::size_t ack = regs().FindWriteWithBits(otg::Diepint(0), otg::kEpIntEpdisd, disable);
  // GRSTCTL TXFFLSH (bit 5) with TXFNUM 0 (10:6).
  const std::size_t flush = regs().FindWrite(otg::kGrstctl, otg::kGrstctlTxfflsh, ack);
  ASSERT_NE(disable, kNone);
  ASSERT_NE(ack, kNone);
  ASSERT_NE(flush, kNone);
  EXPECT_LT(flush, events_.log_at_setup);
}

TEST_F(OtgTest, StallOnEp0AlsoFlushesEp0In) {
  ASSERT_EQ(dcd_.Init(events_), Status::kOk);
  const std::size_t before = regs().log().size();
  dcd_.EndpointStall(0x80);
  EXPECT_NE(regs().FindWriteWithBits(otg::Diepctl(0), otg::kEpctlStall | otg::kEpctlSnak, before),
            kNone);
  EXPECT_NE(regs().FindWrite(otg::kGrstctl, otg::kGrstctlTxfflsh, before), kNone);
  // EP1 IN: TXFNUM 1 -> 1 << 6.
  dcd_.EndpointStall(0x81);
  EXPECT_NE(regs().FindWrite(otg::kGrstctl, otg::kGrstctlTxfflsh | (1U << 6), before), kNone);
}

TEST_F(OtgTest, ReconfigurationDisablesOutEndpointsInTheRm0090Order) {
  ASSERT_EQ(dcd_.Init(events_), Status::kOk);
  regs().Poke(otg::Doepctl(1), otg::kEpctlEpena | otg::kEpctlUsbaep);
  const std::size_t before = regs().log().size();
  dcd_.EndpointCloseAll();
  // SGONAK -> RX FIFO popped up to the NAK entry (GONAKEFF) -> EPDIS | SNAK -> (EPDISD)
  // acknowledged -> CGONAK.
  const std::size_t sgonak = regs().FindWriteWithBits(otg::kDctl, otg::kDctlSgonak, before);
  std::size_t popped = kNone;
  for (std::size_t i = sgonak; i < regs().log().size() && popped == kNone; ++i) {
    const Access& a = regs().log()[i];
    if (a.kind == Access::Kind::kRead && a.address == otg::kGrxstsp) popped = i;
  }
  ASSERT_NE(popped, kNone);
  const std::size_t epdis =
      regs().FindWriteWithBits(otg::Doepctl(1), otg::kEpctlEpdis | otg::kEpctlSnak, popped);
  const std::size_t ack = regs().FindWrite(otg::Doepint(1), otg::kEpIntEpdisd, epdis);
  const std::size_t cgonak = regs().FindWriteWithBits(otg::kDctl, otg::kDctlCgonak, ack);
  ASSERT_NE(sgonak, kNone);
  ASSERT_NE(epdis, kNone);
  ASSERT_NE(ack, kNone);
  ASSERT_NE(cgonak, kNone);
  // Endpoints not enabled are left alone: no global OUT NAK for EP2/EP3.
  EXPECT_EQ(regs().FindWriteWithBits(otg::kDctl, otg::kDctlSgonak, cgonak + 1), kNone);
  EXPECT_EQ(regs().Peek(otg::Doepctl(1)) & otg::kEpctlUsbaep, 0U);
}

TEST_F(OtgTest, InTransfersPendingFollowsEpena) {
  EXPECT_FALSE(dcd_.InTransfersPending());
  regs().Poke(otg::Diepctl(1), otg::kEpctlEpena);
  EXPECT_TRUE(dcd_.InTransfersPending());
}

}  // namespace
}  // namespace vibid::fw::stm32::test
