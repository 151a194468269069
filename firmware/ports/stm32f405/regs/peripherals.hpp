// GPIO (RM0090 §8.4), general-purpose timers TIM2..TIM5 (§18.4), ADC (§13.13), DMA (§10.5),
// USART (§30.6), independent watchdog (§21.4).
#pragma once

#include "mmio.hpp"

namespace vibid::fw::stm32 {

namespace gpio {
inline constexpr Address kPortA = 0x40020000;
inline constexpr Address kPortB = 0x40020400;
inline constexpr Address kPortC = 0x40020800;
inline constexpr Address kModer = 0x00;
inline constexpr Address kOtyper = 0x04;
inline constexpr Address kOspeedr = 0x08;
inline constexpr Address kPupdr = 0x0C;
inline constexpr Address kIdr = 0x10;
inline constexpr Address kBsrr = 0x18;
inline constexpr Address kAfrl = 0x20;
inline constexpr Address kAfrh = 0x24;

enum class Mode : std::uint32_t { kInput = 0, kOutput = 1, kAlternate = 2, kAnalog = 3 };

inline void SetMode(Address port, unsigned pin, Mode mode) {
  Modify(port + kModer, 0x3U << (2 * pin), static_cast<std::uint32_t>(mode) << (2 * pin));
}
/// Alternate function `af` (0..15) on `pin`, very high speed.
inline void SetAlternate(Address port, unsigned pin, std::uint32_t af) {
  const Address afr = port + (pin < 8 ? kAfrl : kAfrh);
  const unsigned shift = 4 * (pin % 8);
  Modify(afr, 0xFU << shift, af << shift);
  Modify(port + kOspeedr, 0x3U << (2 * pin), 0x3U << (2 * pin));
  SetMode(port, pin, Mode::kAlternate);
}
inline void SetPullUp(Address port, unsigned pin) {
  Modify(port + kPupdr, 0x3U << (2 * pin), 0x1U << (2 * pin));
}
}  // namespace gpio

namespace tim {
inline constexpr Address kTim2 = 0x40000000;
inline constexpr Address kTim3 = 0x40000400;
inline constexpr Address kTim4 = 0x40000800;
inline constexpr Address kTim5 = 0x40000C00;
inline constexpr Address kTim11 = 0x40014800;  // APB2 (RM0090 table 1)
inline constexpr Address kCr1 = 0x00;
inline constexpr Address kCr2 = 0x04;
inline constexpr Address kSmcr = 0x08;
inline constexpr Address kDier = 0x0C;
inline constexpr Address kSr = 0x10;
inline constexpr Address kEgr = 0x14;
inline constexpr Address kCcmr1 = 0x18;
inline constexpr Address kCcmr2 = 0x1C;
inline constexpr Address kCcer = 0x20;
inline constexpr Address kCnt = 0x24;
inline constexpr Address kPsc = 0x28;
inline constexpr Address kArr = 0x2C;
inline constexpr Address kCcr1 = 0x34;
inline constexpr Address kCcr3 = 0x3C;
inline constexpr Address kCcr4 = 0x40;
/// TIM5_OR and TIM11_OR, the input remap (RM0090: the TIM5 and TIM11 option registers).
inline constexpr Address kOr = 0x50;

inline constexpr std::uint32_t kCr1Cen = Bit(0);
inline constexpr std::uint32_t kCr1Arpe = Bit(7);
/// CR2 MMS (6:4) = 010: the update event is TRGO (ADC trigger source).
inline constexpr std::uint32_t kCr2MmsUpdate = 0x2U << 4;
/// SMCR SMS (2:0) = 011: encoder mode 3, counting on both TI1 and TI2 edges (x4).
inline constexpr std::uint32_t kSmcrEncoderMode3 = 0x3;
/// CCMR1 CC1S (1:0) = 01 and CC2S (9:8) = 01: IC1 on TI1, IC2 on TI2; IC1F/IC2F (7:4, 15:12)
/// = 0011: fCK_INT, N = 8 glitch filter for the encoder lines.
inline constexpr std::uint32_t kCcmr1EncoderInputs =
    0x1U | (0x3U << 4) | (0x1U << 8) | (0x3U << 12);
/// SMCR TS (6:4) = 000: ITR0, which is TIM2's TRGO for TIM5 (RM0090 table 99, TIMx internal
/// trigger connection); SMS (2:0) = 111: external clock mode 1, one count per trigger edge.
inline constexpr std::uint32_t kSmcrTsItr0 = 0x0U << 4;
inline constexpr std::uint32_t kSmcrExternalClock1 = 0x7;
inline constexpr std::uint32_t kDierUie = Bit(0);
inline constexpr std::uint32_t kDierUde = Bit(8);     ///< DMA request on update.
inline constexpr std::uint32_t kDierCc3de = Bit(11);  ///< DMA request on a channel 3 compare.
inline constexpr std::uint32_t kDierCc4de = Bit(12);  ///< DMA request on a channel 4 compare.
inline constexpr std::uint32_t kDierTde = Bit(14);    ///< DMA request on trigger.
inline constexpr std::uint32_t kSrUif = Bit(0);
inline constexpr std::uint32_t kSrCc1if = Bit(1);
inline constexpr std::uint32_t kSrCc4if = Bit(4);
inline constexpr std::uint32_t kSrCc1of = Bit(9);
inline constexpr std::uint32_t kSrCc4of = Bit(12);
/// CCMR1 CC1S (1:0) = 01: IC1 on TI1; IC1PSC (3:2) = 11: one capture every 8 edges.
inline constexpr std::uint32_t kCcmr1Ic1Every8 = 0x1U | (0x3U << 2);
/// CCMR2 CC4S (9:8) = 01: IC4 on TI4; IC4PSC (11:10) = 11: one capture every 8 edges.
inline constexpr std::uint32_t kCcmr2Ic4Every8 = (0x1U << 8) | (0x3U << 10);
inline constexpr std::uint32_t kCcerCc1e = Bit(0);
inline constexpr std::uint32_t kCcerCc4e = Bit(12);
/// TIM11_OR TI1_RMP (1:0) = 10: channel 1 input is HSE_RTC.
inline constexpr std::uint32_t kTim11OrHseRtc = 0x2;
/// TIM5_OR TI4_RMP (7:6) = 10: channel 4 input is the LSE.
inline constexpr std::uint32_t kTim5OrLse = 0x2U << 6;
inline constexpr std::uint32_t kEgrUg = Bit(0);
}  // namespace tim

namespace adc {
/// ADC1, ADC2, ADC3 and the common registers at 0x000, 0x100, 0x200 and 0x300 from 0x40012000
/// (RM0090 table 1 and the ADC register map, §13.13.19).
inline constexpr Address kAdc1 = 0x40012000;
inline constexpr Address kAdc2 = 0x40012100;
inline constexpr Address kAdc3 = 0x40012200;
inline constexpr Address kCommonCsr = 0x40012300;
inline constexpr Address kCommonCcr = 0x40012304;
/// Common regular data register for multi-ADC mode (RM0090 §13.13.18).
inline constexpr Address kCommonCdr = 0x40012308;
inline constexpr Address kSr = 0x00;
inline constexpr Address kCr1 = 0x04;
inline constexpr Address kCr2 = 0x08;
inline constexpr Address kSmpr1 = 0x0C;
inline constexpr Address kSmpr2 = 0x10;
inline constexpr Address kSqr1 = 0x2C;
inline constexpr Address kSqr3 = 0x34;
inline constexpr Address kDr = 0x4C;

inline constexpr std::uint32_t kSrEoc = Bit(1);
inline constexpr std::uint32_t kSrOvr = Bit(5);
inline constexpr std::uint32_t kCr1Scan = Bit(8);
inline constexpr std::uint32_t kCr1Ovrie = Bit(26);
inline constexpr std::uint32_t kCr2Adon = Bit(0);
inline constexpr std::uint32_t kCr2Dma = Bit(8);
inline constexpr std::uint32_t kCr2Dds = Bit(9);
/// EOCS (10): EOC after each regular conversion. Overrun detection is on only with DMA = 1 or
/// EOCS = 1 (RM0090 §13.8.1): in multi-ADC mode CR2's DMA bit is unused, so EOCS turns it on.
inline constexpr std::uint32_t kCr2Eocs = Bit(10);
inline constexpr std::uint32_t kCr2Swstart = Bit(30);
/// EXTSEL (27:24) = 0110: timer 2 TRGO; EXTEN (29:28) = 01: rising edge.
inline constexpr std::uint32_t kCr2ExtselTim2Trgo = 0x6U << 24;
inline constexpr std::uint32_t kCr2ExtenRising = 0x1U << 28;
/// SQR1 L (23:20): number of conversions minus one.
inline constexpr unsigned kSqr1LPos = 20;
/// ADC common CCR ADCPRE (17:16) = 01: ADCCLK = PCLK2 / 4 = 21 MHz (max 36 MHz).
inline constexpr std::uint32_t kCcrAdcpreDiv4 = 0x1U << 16;
/// CCR MULTI (4:0) = 10110: triple mode, regular simultaneous mode only (RM0090 §13.13.17).
inline constexpr std::uint32_t kCcrMultiTripleRegularSimultaneous = 0x16;
/// CCR DMA (15:14) = 01: DMA mode 1, one request per converted item, ADC1 then ADC2 then ADC3
/// through ADC_CDR (RM0090 §13.9 "DMA requests in multi ADC mode", §13.13.17).
inline constexpr std::uint32_t kCcrDmaMode1 = 0x1U << 14;
/// CCR DDS (13) = 1: DMA requests go on after the last transfer (circular DMA) (§13.13.17).
inline constexpr std::uint32_t kCcrDds = Bit(13);
inline constexpr std::uint32_t kCcrDmaMask = 0x3U << 14;
/// SQR3 SQ1..SQ6: 5-bit channel numbers at bits 0, 5, 10, ... (RM0090 §13.13.11).
constexpr std::uint32_t Sqr3(unsigned position, std::uint32_t channel) {
  return channel << (5 * position);
}
/// CCR TSVREFE (23): connects the temperature sensor and VREFINT (ADC1_IN17).
inline constexpr std::uint32_t kCcrTsvrefe = Bit(23);
inline constexpr std::uint32_t kCcrMultiMask = 0x1F;
/// VREFINT is ADC1's channel 17; SMPR1 holds channels 10..18, SMP17 at bits 23:21.
inline constexpr std::uint32_t kChannelVrefint = 17;
inline constexpr unsigned kSmpr1Smp17Pos = 21;
/// SMPR 3-bit field per channel; 111 = 480 cycles.
inline constexpr std::uint32_t kSample480Cycles = 0x7;
/// SMPR 3-bit field per channel; 011 = 56 cycles.
inline constexpr std::uint32_t kSample56Cycles = 0x3;
}  // namespace adc

namespace dma {
inline constexpr Address kDma1 = 0x40026000;
inline constexpr Address kDma2 = 0x40026400;
inline constexpr Address kLisr = 0x00;
inline constexpr Address kHisr = 0x04;
inline constexpr Address kLifcr = 0x08;
inline constexpr Address kHifcr = 0x0C;
/// Stream n registers start at 0x10 + 0x18 * n.
constexpr Address Stream(Address dma_base, unsigned n) { return dma_base + 0x10 + 0x18 * n; }
inline constexpr Address kSxCr = 0x00;
inline constexpr Address kSxNdtr = 0x04;
inline constexpr Address kSxPar = 0x08;
inline constexpr Address kSxM0ar = 0x0C;
inline constexpr Address kSxFcr = 0x14;

inline constexpr std::uint32_t kCrEn = Bit(0);
inline constexpr std::uint32_t kCrTeie = Bit(2);
inline constexpr std::uint32_t kCrTcie = Bit(4);
inline constexpr std::uint32_t kCrCirc = Bit(8);
inline constexpr std::uint32_t kCrMinc = Bit(10);
inline constexpr std::uint32_t kCrPsize16 = 0x1U << 11;
inline constexpr std::uint32_t kCrMsize16 = 0x1U << 13;
inline constexpr std::uint32_t kCrPlHigh = 0x2U << 16;
inline constexpr unsigned kCrChselPos = 25;
/// LISR/LIFCR stream 0 flags: FEIF0 0, DMEIF0 2, TEIF0 3, HTIF0 4, TCIF0 5.
inline constexpr std::uint32_t kStream0Flags = Bit(0) | Bit(2) | Bit(3) | Bit(4) | Bit(5);
inline constexpr std::uint32_t kStream0Tcif = Bit(5);
inline constexpr std::uint32_t kStream0Teif = Bit(3);
/// The same six-bit group sits at bit 0, 6, 16 and 22 for streams 0..3 (LISR) and 4..7 (HISR).
constexpr unsigned FlagShift(unsigned stream) {
  constexpr unsigned kShift[4] = {0, 6, 16, 22};
  return kShift[stream % 4];
}
constexpr Address FlagStatus(unsigned stream) { return stream < 4 ? kLisr : kHisr; }
constexpr Address FlagClear(unsigned stream) { return stream < 4 ? kLifcr : kHifcr; }
}  // namespace dma

namespace usart {
inline constexpr Address kUsart1 = 0x40011000;
inline constexpr Address kSr = 0x00;
inline constexpr Address kDr = 0x04;
inline constexpr Address kBrr = 0x08;
inline constexpr Address kCr1 = 0x0C;
inline constexpr std::uint32_t kSrOre = Bit(3);
inline constexpr std::uint32_t kSrRxne = Bit(5);
inline constexpr std::uint32_t kSrTxe = Bit(7);
inline constexpr std::uint32_t kCr1Re = Bit(2);
inline constexpr std::uint32_t kCr1Te = Bit(3);
inline constexpr std::uint32_t kCr1Rxneie = Bit(5);
inline constexpr std::uint32_t kCr1Ue = Bit(13);
}  // namespace usart

namespace iwdg {
inline constexpr Address kBase = 0x40003000;
inline constexpr Address kKr = kBase + 0x00;
inline constexpr Address kPr = kBase + 0x04;
inline constexpr Address kRlr = kBase + 0x08;
inline constexpr Address kSr = kBase + 0x0C;
inline constexpr std::uint32_t kKeyStart = 0xCCCC;
inline constexpr std::uint32_t kKeyReload = 0xAAAA;
inline constexpr std::uint32_t kKeyUnlock = 0x5555;
/// PR = 3: LSI / 32.
inline constexpr std::uint32_t kPrDiv32 = 3;
/// SR: PVU (0) and RVU (1) are set while a prescaler/reload update is in progress.
inline constexpr std::uint32_t kSrBusy = 0x3;
}  // namespace iwdg

}  // namespace vibid::fw::stm32
