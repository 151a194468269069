#include "vibid/fw/usb/descriptors.hpp"

#include <algorithm>

namespace vibid::fw::usb {
namespace {

static_assert(kDeviceDescriptor[0] == kDeviceDescriptor.size());
static_assert(kConfigurationDescriptor[0] == kConfigurationHeaderSize);
static_assert(kHidReportDescriptor.size() == 25,
              "HID report descriptor length is in the HID descriptor");

}  // namespace

std::size_t BuildStringDescriptor(const char* text, std::size_t text_length,
                                  std::span<std::uint8_t, kMaxStringDescriptorSize> out) {
  const std::size_t limit = std::min(text_length, kMaxSerialLength);
  std::size_t n = 0;
  while (n < limit && text[n] != '\0') {
    // ASCII maps to UTF-16 code units unchanged; anything else is replaced so the host never
    // sees an invalid descriptor.
    const auto c = static_cast<std::uint8_t>(text[n]);
    out[2 + 2 * n] = c < 0x80 ? c : static_cast<std::uint8_t>('?');
    out[3 + 2 * n] = 0;
    ++n;
  }
  const auto length = static_cast<std::uint8_t>(2 + 2 * n);
  out[0] = length;
  out[1] = static_cast<std::uint8_t>(DescriptorType::kString);
  return length;
}

}  // namespace vibid::fw::usb
