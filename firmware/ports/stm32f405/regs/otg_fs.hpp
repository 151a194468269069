// USB on-the-go full-speed core, device mode (RM0090 §34.16).
#pragma once

#include "mmio.hpp"

namespace vibid::fw::stm32::otg {

inline constexpr Address kBase = 0x50000000;

// Core global registers.
inline constexpr Address kGotgctl = kBase + 0x000;
inline constexpr Address kGahbcfg = kBase + 0x008;
inline constexpr Address kGusbcfg = kBase + 0x00C;
inline constexpr Address kGrstctl = kBase + 0x010;
inline constexpr Address kGintsts = kBase + 0x014;
inline constexpr Address kGintmsk = kBase + 0x018;
inline constexpr Address kGrxstsp = kBase + 0x020;
inline constexpr Address kGrxfsiz = kBase + 0x024;
inline constexpr Address kDieptxf0 = kBase + 0x028;  ///< Endpoint 0 TX FIFO size (device mode).
inline constexpr Address kGccfg = kBase + 0x038;
/// TX FIFO size for IN endpoint n >= 1.
constexpr Address Dieptxf(unsigned n) { return kBase + 0x104 + 4 * (n - 1); }

inline constexpr std::uint32_t kGahbcfgGint = Bit(0);
inline constexpr std::uint32_t kGusbcfgPhysel = Bit(6);
inline constexpr unsigned kGusbcfgTrdtPos = 10;
inline constexpr std::uint32_t kGusbcfgTrdtMask = 0xFU << 10;
inline constexpr std::uint32_t kGusbcfgFdmod = Bit(30);
inline constexpr std::uint32_t kGrstctlCsrst = Bit(0);
inline constexpr std::uint32_t kGrstctlRxfflsh = Bit(4);
inline constexpr std::uint32_t kGrstctlTxfflsh = Bit(5);
inline constexpr unsigned kGrstctlTxfnumPos = 6;
inline constexpr std::uint32_t kGrstctlTxfnumAll = 0x10U << 6;
inline constexpr std::uint32_t kGrstctlAhbidl = Bit(31);
inline constexpr std::uint32_t kGccfgPwrdwn = Bit(16);
inline constexpr std::uint32_t kGccfgNovbussens = Bit(21);
/// VBUSBSEN (19): B-device VBUS sensing on PA9; the D+ pull-up follows VBUS (RM0090 §34.16.1).
inline constexpr std::uint32_t kGccfgVbusbsen = Bit(19);

// GINTSTS / GINTMSK
inline constexpr std::uint32_t kIntCmod = Bit(0);  ///< GINTSTS: 0 = device mode, 1 = host mode.
/// GINTSTS SOF: a start-of-frame token arrived (every 1 ms at full speed); write 1 to clear.
inline constexpr std::uint32_t kIntSof = Bit(3);
inline constexpr std::uint32_t kIntRxflvl = Bit(4);
inline constexpr std::uint32_t kIntGonakeff = Bit(7);  ///< Global OUT NAK effective.
inline constexpr std::uint32_t kIntUsbsusp = Bit(11);
inline constexpr std::uint32_t kIntUsbrst = Bit(12);
inline constexpr std::uint32_t kIntEnumdne = Bit(13);
inline constexpr std::uint32_t kIntIepint = Bit(18);
inline constexpr std::uint32_t kIntOepint = Bit(19);
inline constexpr std::uint32_t kIntWkupint = Bit(31);

// GRXSTSP: EPNUM 3:0, BCNT 14:4, PKTSTS 20:17.
inline constexpr std::uint32_t kRxstsPktOutData = 2;
inline constexpr std::uint32_t kRxstsPktOutDone = 3;
inline constexpr std::uint32_t kRxstsPktSetupDone = 4;
inline constexpr std::uint32_t kRxstsPktSetupData = 6;

// Device registers.
inline constexpr Address kDcfg = kBase + 0x800;
inline constexpr Address kDctl = kBase + 0x804;
inline constexpr Address kDsts = kBase + 0x808;
inline constexpr Address kDiepmsk = kBase + 0x810;
inline constexpr Address kDoepmsk = kBase + 0x814;
inline constexpr Address kDaint = kBase + 0x818;
inline constexpr Address kDaintmsk = kBase + 0x81C;
inline constexpr Address kDiepempmsk = kBase + 0x834;
inline constexpr Address kPcgcctl = kBase + 0xE00;
/// PCGCCTL STPPCLK (0): stops the PHY clock while the bus is suspended (RM0090 §34.16.5, the
/// device-mode suspend steps of §34.13); DSTS SUSPSTS (0): the core sees the bus suspended.
inline constexpr std::uint32_t kPcgcctlStppclk = Bit(0);
inline constexpr std::uint32_t kDstsSuspsts = Bit(0);

inline constexpr std::uint32_t kDcfgDspdFull = 0x3;
inline constexpr unsigned kDcfgDadPos = 4;
inline constexpr std::uint32_t kDcfgDadMask = 0x7FU << 4;
inline constexpr std::uint32_t kDctlSdis = Bit(1);
inline constexpr std::uint32_t kDctlCginak = Bit(8);
inline constexpr std::uint32_t kDctlSgonak = Bit(9);
inline constexpr std::uint32_t kDctlCgonak = Bit(10);
inline constexpr std::uint32_t kEpIntXfrc = Bit(0);
inline constexpr std::uint32_t kEpIntEpdisd = Bit(1);  ///< Endpoint disabled.
inline constexpr std::uint32_t kEpIntStup = Bit(3);    ///< DOEPINT: SETUP phase done.
inline constexpr std::uint32_t kEpIntInepne = Bit(6);  ///< DIEPINT: IN endpoint NAK effective.
inline constexpr std::uint32_t kEpIntTxfe = Bit(7);    ///< DIEPINT: TX FIFO empty.

constexpr Address Diepctl(unsigned n) { return kBase + 0x900 + 0x20 * n; }
constexpr Address Diepint(unsigned n) { return kBase + 0x908 + 0x20 * n; }
constexpr Address Dieptsiz(unsigned n) { return kBase + 0x910 + 0x20 * n; }
constexpr Address Dtxfsts(unsigned n) { return kBase + 0x918 + 0x20 * n; }
constexpr Address Doepctl(unsigned n) { return kBase + 0xB00 + 0x20 * n; }
constexpr Address Doepint(unsigned n) { return kBase + 0xB08 + 0x20 * n; }
constexpr Address Doeptsiz(unsigned n) { return kBase + 0xB10 + 0x20 * n; }
/// Data FIFO n push (IN) / pop (any OUT) window.
constexpr Address Fifo(unsigned n) { return kBase + 0x1000 + 0x1000 * n; }

// DIEPCTL / DOEPCTL
inline constexpr std::uint32_t kEpctlMpsizMask = 0x7FF;
inline constexpr std::uint32_t kEpctlUsbaep = Bit(15);
inline constexpr unsigned kEpctlEptypPos = 18;
inline constexpr std::uint32_t kEpctlStall = Bit(21);
inline constexpr unsigned kEpctlTxfnumPos = 22;
inline constexpr std::uint32_t kEpctlCnak = Bit(26);
inline constexpr std::uint32_t kEpctlSnak = Bit(27);
inline constexpr std::uint32_t kEpctlSd0pid = Bit(28);
inline constexpr std::uint32_t kEpctlEpdis = Bit(30);
inline constexpr std::uint32_t kEpctlEpena = Bit(31);

// DIEPTSIZ / DOEPTSIZ: XFRSIZ 18:0, PKTCNT 28:19, STUPCNT 30:29 (DOEPTSIZ0).
inline constexpr unsigned kTsizPktcntPos = 19;
inline constexpr std::uint32_t kDoeptsiz0Stupcnt3 = 0x3U << 29;

/// FIFO RAM is 1.25 KiB = 320 words (RM0090 §34.11.3).
inline constexpr std::uint32_t kFifoWords = 320;

}  // namespace vibid::fw::stm32::otg
