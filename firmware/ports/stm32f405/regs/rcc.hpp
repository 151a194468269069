// Reset and clock control (RM0090 §7.3), power control (§5.4), flash interface (§3.9).
#pragma once

#include "mmio.hpp"

namespace vibid::fw::stm32 {

namespace rcc {
inline constexpr Address kBase = 0x40023800;
inline constexpr Address kCr = kBase + 0x00;
inline constexpr Address kPllcfgr = kBase + 0x04;
inline constexpr Address kCfgr = kBase + 0x08;
inline constexpr Address kCir = kBase + 0x0C;
inline constexpr Address kAhb1enr = kBase + 0x30;
inline constexpr Address kAhb2enr = kBase + 0x34;
inline constexpr Address kAhb3enr = kBase + 0x38;
inline constexpr Address kApb1enr = kBase + 0x40;
inline constexpr Address kApb2enr = kBase + 0x44;
inline constexpr Address kBdcr = kBase + 0x70;
inline constexpr Address kCsr = kBase + 0x74;

// RCC_CR
inline constexpr std::uint32_t kCrHsiOn = Bit(0);
inline constexpr std::uint32_t kCrHsiRdy = Bit(1);
inline constexpr std::uint32_t kCrHseOn = Bit(16);
inline constexpr std::uint32_t kCrHseRdy = Bit(17);
inline constexpr std::uint32_t kCrCssOn = Bit(19);
inline constexpr std::uint32_t kCrPllOn = Bit(24);
inline constexpr std::uint32_t kCrPllRdy = Bit(25);
inline constexpr std::uint32_t kCrPlli2sOn = Bit(26);

// RCC_PLLCFGR: PLLM 5:0, PLLN 14:6, PLLP 17:16 (0 = /2), PLLSRC 22 (1 = HSE), PLLQ 27:24.
inline constexpr unsigned kPllcfgrPllmPos = 0;
inline constexpr unsigned kPllcfgrPllnPos = 6;
inline constexpr unsigned kPllcfgrPllpPos = 16;
inline constexpr std::uint32_t kPllcfgrSrcHse = Bit(22);
inline constexpr unsigned kPllcfgrPllqPos = 24;

// RCC_CFGR: SW 1:0, SWS 3:2, HPRE 7:4, PPRE1 12:10, PPRE2 15:13.
inline constexpr std::uint32_t kCfgrSwMask = 0x3;
inline constexpr std::uint32_t kCfgrSwHsi = 0x0;
inline constexpr std::uint32_t kCfgrSwPll = 0x2;
inline constexpr std::uint32_t kCfgrSwsMask = 0x3U << 2;
inline constexpr std::uint32_t kCfgrSwsPll = 0x2U << 2;
inline constexpr std::uint32_t kCfgrSwsHsi = 0x0U << 2;
inline constexpr std::uint32_t kCfgrPpre1Div4 = 0x5U << 10;
inline constexpr std::uint32_t kCfgrPpre2Div2 = 0x4U << 13;
inline constexpr std::uint32_t kCfgrPrescalerMask = (0xFU << 4) | (0x7U << 10) | (0x7U << 13);
/// RTCPRE (20:16): HSE_RTC = HSE / RTCPRE (2..31), which TIM11 channel 1 can capture (§7.3.3).
inline constexpr unsigned kCfgrRtcprePos = 16;
inline constexpr std::uint32_t kCfgrRtcpreMask = 0x1FU << 16;
/// PLLCFGR PLLSRC (22) = 0: the PLL runs from the HSI.
inline constexpr std::uint32_t kPllcfgrSrcHsi = 0;

// Clock enables.
inline constexpr std::uint32_t kAhb1GpioA = Bit(0);
inline constexpr std::uint32_t kAhb1GpioB = Bit(1);
inline constexpr std::uint32_t kAhb1GpioC = Bit(2);
inline constexpr std::uint32_t kAhb1Dma1 = Bit(21);
inline constexpr std::uint32_t kAhb1Dma2 = Bit(22);
inline constexpr std::uint32_t kAhb2OtgFs = Bit(7);
/// AHB1ENR's only bit set at reset: CCMDATARAMEN (bit 20); reset value 0x00100000 (RM0090
/// §7.3.10). AHB2ENR, AHB3ENR, APB1ENR and APB2ENR reset to 0 (§7.3.11 to §7.3.14).
inline constexpr std::uint32_t kAhb1CcmDataRam = Bit(20);
inline constexpr std::uint32_t kApb1Tim2 = Bit(0);
inline constexpr std::uint32_t kApb1Tim3 = Bit(1);
inline constexpr std::uint32_t kApb1Tim4 = Bit(2);
inline constexpr std::uint32_t kApb1Tim5 = Bit(3);
inline constexpr std::uint32_t kApb1Pwr = Bit(28);
inline constexpr std::uint32_t kApb2Usart1 = Bit(4);
inline constexpr std::uint32_t kApb2Adc1 = Bit(8);
inline constexpr std::uint32_t kApb2Adc2 = Bit(9);  // RM0090 §7.3.14
inline constexpr std::uint32_t kApb2Adc3 = Bit(10);
inline constexpr std::uint32_t kApb2Syscfg = Bit(14);
inline constexpr std::uint32_t kApb2Tim11 = Bit(18);  // RM0090 §7.3.14

// RCC_BDCR (§7.3.20, backup domain: written only with PWR_CR DBP set): LSEON 0, LSERDY 1.
inline constexpr std::uint32_t kBdcrLseOn = Bit(0);
inline constexpr std::uint32_t kBdcrLseRdy = Bit(1);

// RCC_CSR: reset flags (set by hardware, cleared by RMVF).
inline constexpr std::uint32_t kCsrLsiOn = Bit(0);
inline constexpr std::uint32_t kCsrLsiRdy = Bit(1);
inline constexpr std::uint32_t kCsrRmvf = Bit(24);
inline constexpr std::uint32_t kCsrBorRstf = Bit(25);
inline constexpr std::uint32_t kCsrPinRstf = Bit(26);
inline constexpr std::uint32_t kCsrPorRstf = Bit(27);
inline constexpr std::uint32_t kCsrSftRstf = Bit(28);
inline constexpr std::uint32_t kCsrIwdgRstf = Bit(29);
inline constexpr std::uint32_t kCsrWwdgRstf = Bit(30);
inline constexpr std::uint32_t kCsrLpwrRstf = Bit(31);
}  // namespace rcc

namespace pwr {
inline constexpr Address kCr = 0x40007000;
/// VOS (bit 14): regulator scale 1, needed above 144 MHz.
inline constexpr std::uint32_t kCrVos = Bit(14);
/// DBP (bit 8): write access to the backup domain (RCC_BDCR, RTC), off after reset (§5.4.1).
inline constexpr std::uint32_t kCrDbp = Bit(8);
}  // namespace pwr

namespace flash {
inline constexpr Address kBase = 0x40023C00;
inline constexpr Address kAcr = kBase + 0x00;
inline constexpr Address kKeyr = kBase + 0x04;
inline constexpr Address kSr = kBase + 0x0C;
inline constexpr Address kCr = kBase + 0x10;
inline constexpr Address kOptcr = kBase + 0x14;
inline constexpr std::uint32_t kKey1 = 0x45670123;
inline constexpr std::uint32_t kKey2 = 0xCDEF89AB;

// FLASH_ACR: LATENCY 2:0 (wait states), PRFTEN 8, ICEN 9, DCEN 10, ICRST 11, DCRST 12 (the
// cache resets work only while the cache is disabled).
inline constexpr std::uint32_t kAcrLatencyMask = 0x7;
inline constexpr std::uint32_t kAcrPrften = Bit(8);
inline constexpr std::uint32_t kAcrIcen = Bit(9);
inline constexpr std::uint32_t kAcrDcen = Bit(10);
inline constexpr std::uint32_t kAcrIcrst = Bit(11);
inline constexpr std::uint32_t kAcrDcrst = Bit(12);

// FLASH_SR
inline constexpr std::uint32_t kSrEop = Bit(0);
inline constexpr std::uint32_t kSrOperr = Bit(1);
inline constexpr std::uint32_t kSrWrperr = Bit(4);
inline constexpr std::uint32_t kSrPgaerr = Bit(5);
inline constexpr std::uint32_t kSrPgperr = Bit(6);
inline constexpr std::uint32_t kSrPgserr = Bit(7);
inline constexpr std::uint32_t kSrBsy = Bit(16);
inline constexpr std::uint32_t kSrErrors = kSrOperr | kSrWrperr | kSrPgaerr | kSrPgperr | kSrPgserr;

// FLASH_CR: PG 0, SER 1, SNB 6:3, PSIZE 9:8 (2 = x32, needs 2.7-3.6 V), STRT 16, LOCK 31.
inline constexpr std::uint32_t kCrPg = Bit(0);
inline constexpr std::uint32_t kCrSer = Bit(1);
inline constexpr unsigned kCrSnbPos = 3;
inline constexpr std::uint32_t kCrSnbMask = 0xFU << 3;
inline constexpr std::uint32_t kCrPsizeX8 = 0x0U << 8;
inline constexpr std::uint32_t kCrPsizeX32 = 0x2U << 8;
inline constexpr std::uint32_t kCrPsizeMask = 0x3U << 8;
inline constexpr std::uint32_t kCrStrt = Bit(16);
inline constexpr std::uint32_t kCrLock = Bit(31);

// FLASH_OPTCR (RM0090 §3.9.10, reset value 0x0FFFAAED): BOR_LEV 3:2, loaded from the user
// option bytes at reset: 00 level 3, 01 level 2, 10 level 1, 11 off (POR/PDR only).
inline constexpr unsigned kOptcrBorLevPos = 2;
inline constexpr std::uint32_t kOptcrBorLevMask = 0x3U << 2;
/// OPTLOCK (0): the register is write-protected (set at reset); OPTSTRT (1): programs the option
/// bytes from the register; RDP 15:8 (read protection) and nWRP 27:16 are written as read.
inline constexpr std::uint32_t kOptcrOptlock = Bit(0);
inline constexpr std::uint32_t kOptcrOptstrt = Bit(1);
/// FLASH_OPTKEYR (0x08) and its unlock keys (RM0090 §3.7.2, "Unlocking the option control
/// register").
inline constexpr Address kOptkeyr = kBase + 0x08;
inline constexpr std::uint32_t kOptKey1 = 0x08192A3B;
inline constexpr std::uint32_t kOptKey2 = 0x4C5D6E7F;
}  // namespace flash

/// Device electronic signature (RM0090 §39.1): the 96-bit unique id.
namespace uid {
inline constexpr Address kBase = 0x1FFF7A10;
}
/// System memory holding the ROM bootloader (RM0090 §2.4, AN2606).
inline constexpr Address kSystemMemory = 0x1FFF0000;

}  // namespace vibid::fw::stm32
