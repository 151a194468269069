#include "vibid/device/usb_control.hpp"

#include <string>

#include "vibid/device/error.hpp"

namespace vibid::device {

std::vector<std::uint8_t> GetDescriptor(UsbControl& usb, std::uint8_t type, std::uint8_t index,
                                        std::uint16_t length, std::uint16_t language) {
  Setup s;
  s.request_type = 0x80;
  s.request = kGetDescriptor;
  s.value = static_cast<std::uint16_t>((type << 8) | index);
  s.index = language;
  s.length = length;
  return usb.Control(s, {}, std::chrono::milliseconds(1000));
}

std::string GetStringDescriptor(UsbControl& usb, std::uint8_t index) {
  const std::vector<std::uint8_t> d = GetDescriptor(usb, kDescriptorString, index, 255, 0x0409);
  if (d.size() < 2 || d[1] != kDescriptorString) throw DeviceError("malformed string descriptor");
  std::string s;
  const std::size_t end = std::min<std::size_t>(d.size(), d[0]);
  for (std::size_t i = 2; i + 1 < end; i += 2) {
    s.push_back(d[i + 1] == 0 && d[i] < 0x80 ? static_cast<char>(d[i]) : '?');
  }
  return s;
}

}  // namespace vibid::device
