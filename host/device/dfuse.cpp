#include "vibid/device/dfuse.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>

#include "vibid/common/error.hpp"
#include "vibid/device/error.hpp"

namespace vibid::device {
namespace {

constexpr std::uint8_t kRequestOut = 0x21;  // class, interface, host-to-device
constexpr std::uint8_t kRequestIn = 0xA1;
constexpr std::chrono::milliseconds kTimeout{5000};

constexpr std::uint8_t Code(dfu::Request r) { return static_cast<std::uint8_t>(r); }

std::string Hex(std::uint32_t v) {
  char b[11];
  std::snprintf(b, sizeof(b), "0x%08x", v);
  return b;
}

std::array<std::uint8_t, 5> Command(dfu::DfuSeCommand command, std::uint32_t address) {
  return {static_cast<std::uint8_t>(command), static_cast<std::uint8_t>(address),
          static_cast<std::uint8_t>(address >> 8), static_cast<std::uint8_t>(address >> 16),
          static_cast<std::uint8_t>(address >> 24)};
}

}  // namespace

std::vector<DfuSeSector> ParseDfuSeLayout(const std::string& layout) {
  const auto bad = [&] { throw DeviceError("malformed DfuSe memory layout '" + layout + "'"); };
  const std::size_t a = layout.find('/');
  const std::size_t b = a == std::string::npos ? a : layout.find('/', a + 1);
  if (layout.empty() || layout[0] != '@' || b == std::string::npos) bad();
  char* end = nullptr;
  std::uint64_t address = std::strtoull(layout.c_str() + a + 1, &end, 16);
  if (end != layout.c_str() + b) bad();
  std::vector<DfuSeSector> out;
  std::size_t at = b + 1;
  while (at < layout.size()) {
    const unsigned long count = std::strtoul(layout.c_str() + at, &end, 10);
    if (*end != '*' || count == 0) bad();
    const unsigned long size = std::strtoul(end + 1, &end, 10);
    std::uint64_t unit = 1;
    if (*end == 'K')
      unit = 1024;
    else if (*end == 'M')
      unit = 1024 * 1024;
    else if (*end != 'B')
      bad();
    ++end;
    if (*end == '\0' || size == 0) bad();
    ++end;  // the attribute letter (a..g)
    for (unsigned long i = 0; i < count; ++i) {
      if (address + size * unit > 0x100000000ull) bad();
      out.push_back(DfuSeSector{static_cast<std::uint32_t>(address),
                                static_cast<std::uint32_t>(size * unit)});
      address += size * unit;
    }
    at = static_cast<std::size_t>(end - layout.c_str());
    if (at < layout.size()) {
      if (layout[at] == '/') break;  // a further memory segment: the first one is the flash
      if (layout[at] != ',') bad();
      ++at;
    }
  }
  if (out.empty()) bad();
  return out;
}

DfuSe::DfuSe(UsbControl& usb, std::uint8_t interface, std::uint16_t transfer_size)
    : usb_(&usb), interface_(interface), transfer_size_(transfer_size) {}

DfuSe DfuSe::Open(UsbControl& usb, std::vector<DfuSeSector>& layout) {
  const std::vector<std::uint8_t> head = GetDescriptor(usb, kDescriptorConfiguration, 0, 9);
  if (head.size() != 9) throw DeviceError("malformed configuration descriptor from the bootloader");
  const std::vector<std::uint8_t> cfg = GetDescriptor(
      usb, kDescriptorConfiguration, 0, static_cast<std::uint16_t>(head[2] | (head[3] << 8)));
  int interface = -1;
  std::uint8_t name_index = 0;
  std::uint16_t transfer = 0;
  bool in_dfu = false;
  for (std::size_t i = 0; i + 1 < cfg.size() && cfg[i] >= 2; i += cfg[i]) {
    const std::uint8_t* p = &cfg[i];
    if (p[1] == 4 && i + 8 < cfg.size()) {
      in_dfu = p[5] == 0xFE && p[6] == 0x01;
      if (in_dfu && interface < 0 && p[3] == 0) {
        interface = p[2];
        name_index = p[8];
      }
    } else if (p[1] == 0x21 && in_dfu && i + 6 < cfg.size()) {
      transfer = static_cast<std::uint16_t>(p[5] | (p[6] << 8));
    }
  }
  if (interface < 0 || transfer == 0) throw DeviceError("the device has no DfuSe interface");
  if (name_index == 0) throw DeviceError("the DfuSe interface does not describe its memory");
  layout = ParseDfuSeLayout(GetStringDescriptor(usb, name_index));
  Setup set;
  set.request = kSetConfiguration;
  set.value = head[5];
  static_cast<void>(usb.Control(set, {}, kTimeout));
  return DfuSe(usb, static_cast<std::uint8_t>(interface), transfer);
}

dfu::StatusReply DfuSe::GetStatus() {
  Setup s{kRequestIn, Code(dfu::Request::kGetStatus), 0, interface_, dfu::kStatusReplyBytes};
  const std::vector<std::uint8_t> r = usb_->Control(s, {}, kTimeout);
  if (r.size() != dfu::kStatusReplyBytes) throw DeviceError("malformed DFU_GETSTATUS answer");
  return dfu::DecodeStatusReply(std::span<const std::uint8_t, dfu::kStatusReplyBytes>(r));
}

void DfuSe::ClearStatus() {
  static_cast<void>(usb_->Control(
      Setup{kRequestOut, Code(dfu::Request::kClrStatus), 0, interface_, 0}, {}, kTimeout));
}
void DfuSe::Abort() {
  static_cast<void>(usb_->Control(Setup{kRequestOut, Code(dfu::Request::kAbort), 0, interface_, 0},
                                  {}, kTimeout));
}

dfu::StatusReply DfuSe::Settle(const std::string& what) {
  for (int i = 0; i < 10000; ++i) {
    const dfu::StatusReply st = GetStatus();
    if (st.state == dfu::State::kError || st.status != dfu::Status::kOk) {
      ClearStatus();
      throw DeviceError(what + " failed in the bootloader (DFU status " +
                        std::to_string(static_cast<int>(st.status)) + ")");
    }
    if (st.state != dfu::State::kDnBusy) return st;
    std::this_thread::sleep_for(std::chrono::milliseconds(st.poll_timeout_ms));
  }
  throw DeviceError(what + ": the bootloader stayed busy");
}

void DfuSe::Dnload(std::uint16_t block, std::span<const std::uint8_t> data,
                   const std::string& what) {
  Setup s{kRequestOut, Code(dfu::Request::kDnload), block, interface_,
          static_cast<std::uint16_t>(data.size())};
  static_cast<void>(usb_->Control(s, data, kTimeout));
  const dfu::StatusReply st = Settle(what);
  if (!data.empty() && st.state != dfu::State::kDnloadIdle) {
    throw DeviceError(what + ": the bootloader is in DFU state " +
                      std::to_string(static_cast<int>(st.state)));
  }
}

void DfuSe::SetAddress(std::uint32_t address) {
  Dnload(0, Command(dfu::DfuSeCommand::kSetAddressPointer, address), "set address " + Hex(address));
}

void DfuSe::EraseSector(std::uint32_t address) {
  Dnload(0, Command(dfu::DfuSeCommand::kErase, address), "erase at " + Hex(address));
}

void DfuSe::Download(std::uint16_t block, std::span<const std::uint8_t> data) {
  Dnload(block, data, "download of block " + std::to_string(block));
}

std::vector<std::uint8_t> DfuSe::Upload(std::uint16_t block, std::uint16_t length) {
  return usb_->Control(Setup{kRequestIn, Code(dfu::Request::kUpload), block, interface_, length},
                       {}, kTimeout);
}

void DfuSe::Leave(std::uint32_t address) {
  SetAddress(address);
  Setup s{kRequestOut, Code(dfu::Request::kDnload), 0, interface_, 0};
  static_cast<void>(usb_->Control(s, {}, kTimeout));
  // The bootloader answers this GETSTATUS with dfuMANIFEST and starts the application; a link
  // that drops right after is the expected end.
  try {
    static_cast<void>(GetStatus());
  } catch (const DeviceError&) {
  }
}

FlashPlan PlanFlash(const std::vector<DfuSeSector>& layout, std::span<const std::uint8_t> image,
                    std::uint32_t address, std::span<const FlashRange> keep) {
  if (image.empty()) throw InputError("the image is empty");
  const std::uint64_t end = std::uint64_t{address} + image.size();
  const std::uint64_t flash_end =
      layout.empty() ? 0 : std::uint64_t{layout.back().address} + layout.back().bytes;
  if (layout.empty() || address < layout.front().address || end > flash_end) {
    throw InputError("the image (" + std::to_string(image.size()) + " bytes at " + Hex(address) +
                     ") does not fit the flash (" +
                     std::to_string(flash_end - (layout.empty() ? 0 : layout.front().address)) +
                     " bytes at " + Hex(layout.empty() ? 0 : layout.front().address) + ")");
  }
  FlashPlan plan;
  for (const DfuSeSector& s : layout) {
    const std::uint64_t s_end = std::uint64_t{s.address} + s.bytes;
    if (s_end <= address || s.address >= end) continue;
    const std::uint64_t from = std::max<std::uint64_t>(s.address, address);
    const std::uint64_t to = std::min(s_end, end);
    const bool kept = std::any_of(keep.begin(), keep.end(), [&](const FlashRange& k) {
      return k.address < s_end && std::uint64_t{k.address} + k.bytes > s.address;
    });
    if (kept) {
      const auto part = image.subspan(static_cast<std::size_t>(from - address),
                                      static_cast<std::size_t>(to - from));
      const auto data =
          std::find_if(part.begin(), part.end(), [](std::uint8_t b) { return b != 0xFF; });
      if (data != part.end()) {
        const auto at =
            static_cast<std::uint32_t>(from + static_cast<std::uint64_t>(data - part.begin()));
        throw InputError("the image has data at " + Hex(at) + ", in the sector at " +
                         Hex(s.address) +
                         " that holds the calibration and is never flashed; leave it 0xff (objcopy "
                         "--gap-fill 0xff)");
      }
      continue;
    }
    plan.erase.push_back(s.address);
    if (!plan.write.empty() &&
        std::uint64_t{plan.write.back().address} + plan.write.back().bytes == from) {
      plan.write.back().bytes += static_cast<std::uint32_t>(to - from);
    } else {
      plan.write.push_back(
          FlashRange{static_cast<std::uint32_t>(from), static_cast<std::uint32_t>(to - from)});
    }
  }
  return plan;
}

void FlashImage(DfuSe& dfu, const std::vector<DfuSeSector>& layout,
                std::span<const std::uint8_t> image, std::uint32_t address,
                std::span<const FlashRange> keep, const FlashProgress& progress) {
  FlashPlan plan;
  try {
    plan = PlanFlash(layout, image, address, keep);
  } catch (const InputError& e) {
    throw DeviceError(std::string("the bootloader's flash layout refuses this image: ") + e.what());
  }
  const dfu::StatusReply start = dfu.GetStatus();
  if (start.state == dfu::State::kError) dfu.ClearStatus();
  if (start.state != dfu::State::kIdle) dfu.Abort();
  for (std::size_t i = 0; i < plan.erase.size(); ++i) {
    dfu.EraseSector(plan.erase[i]);
    if (progress) progress("erase", i + 1, plan.erase.size());
  }
  // Each part is written from its own address pointer, block 2 onwards (UM0424 §6.2).
  const std::size_t ts = dfu.transfer_size();
  std::size_t blocks = 0;
  for (const FlashRange& r : plan.write) blocks += (r.bytes + ts - 1) / ts;
  const auto part_of = [&](const FlashRange& r) {
    return image.subspan(r.address - address, r.bytes);
  };
  std::size_t done = 0;
  for (const FlashRange& r : plan.write) {
    const auto part = part_of(r);
    dfu.SetAddress(r.address);
    for (std::size_t b = 0; b * ts < part.size(); ++b) {
      dfu.Download(static_cast<std::uint16_t>(b + 2),
                   part.subspan(b * ts, std::min(ts, part.size() - b * ts)));
      if (progress) progress("download", ++done, blocks);
    }
  }
  // Read back: back to dfuIDLE (DNLOAD is not allowed in dfuUPLOAD-IDLE), set the pointer,
  // dfuIDLE again, then UPLOAD blocks from 2.
  done = 0;
  for (const FlashRange& r : plan.write) {
    const auto part = part_of(r);
    dfu.Abort();
    dfu.SetAddress(r.address);
    dfu.Abort();
    for (std::size_t b = 0; b * ts < part.size(); ++b) {
      const std::size_t n = std::min(ts, part.size() - b * ts);
      const std::vector<std::uint8_t> got =
          dfu.Upload(static_cast<std::uint16_t>(b + 2), static_cast<std::uint16_t>(n));
      const auto want = part.subspan(b * ts, n);
      if (got.size() != n)
        throw DeviceError("verify: the block at " +
                          Hex(static_cast<std::uint32_t>(r.address + b * ts)) + " read back short");
      const auto diff = std::mismatch(want.begin(), want.end(), got.begin());
      if (diff.first != want.end()) {
        const auto at = static_cast<std::uint32_t>(
            r.address + b * ts + static_cast<std::size_t>(diff.first - want.begin()));
        throw DeviceError("verify failed at " + Hex(at) + ": the flash does not hold the image");
      }
      if (progress) progress("verify", ++done, blocks);
    }
  }
  dfu.Abort();
  dfu.Leave(address);
}

}  // namespace vibid::device
