#include "vibid/device/select.hpp"

#include "vibid/common/error.hpp"
#include "vibid/common/text_input.hpp"
#include "vibid/device/error.hpp"
#include <cstdlib>

#include "vibid/device/hid_transport.hpp"
#include "vibid/device/serial_transport.hpp"
#include "vibid/device/usbip_transport.hpp"

namespace vibid::device {
namespace {

constexpr const char* kUsage = "expected hid[:SERIAL], usbip://HOST[:PORT], serial:PATH or qemu";
constexpr const char* kDefaultUsbipHost = "127.0.0.1";
constexpr int kDefaultUsbipPort = 3240;

bool StartsWith(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }

}  // namespace

DeviceChoice ChooseDevice(const std::string& option_value) {
  if (!option_value.empty()) return {option_value, "--device"};
  const char* variable = std::getenv("VIBID_DEVICE");
  if (variable != nullptr && *variable != '\0') return {variable, "VIBID_DEVICE"};
  return {};
}

DeviceSpec ParseDeviceSpec(const std::string& text, const std::string& origin) {
  DeviceSpec spec;
  const auto bad = [&](const std::string& why) {
    throw InputError(origin + " '" + Printable(text) + "': " + why);
  };
  if (text.empty()) return spec;
  if (text == "hid" || StartsWith(text, "hid:")) {
    spec.kind = DeviceSpec::Kind::kHid;
    spec.serial = text.size() > 4 ? text.substr(4) : "";
    if (text.size() == 4) bad("empty serial number after 'hid:'");
    return spec;
  }
  if (StartsWith(text, "usbip://")) {
    spec.kind = DeviceSpec::Kind::kUsbip;
    std::string rest = text.substr(8);
    if (!rest.empty() && rest.back() == '/') rest.pop_back();
    const std::size_t colon = rest.rfind(':');
    spec.host = colon == std::string::npos ? rest : rest.substr(0, colon);
    if (colon != std::string::npos) {
      const std::string port = rest.substr(colon + 1);
      char* end = nullptr;
      const long p = std::strtol(port.c_str(), &end, 10);
      if (port.empty() || *end != '\0' || p < 1 || p > 65535)
        bad("port must be a number from 1 to 65535");
      spec.port = static_cast<int>(p);
    }
    if (spec.host.empty()) bad("missing host");
    return spec;
  }
  if (StartsWith(text, "serial:")) {
    spec.kind = DeviceSpec::Kind::kSerial;
    spec.path = text.substr(7);
    if (spec.path.empty()) bad("missing path after 'serial:'");
    return spec;
  }
  if (text == "qemu") {
    spec.kind = DeviceSpec::Kind::kSerial;
    const char* sock = std::getenv("VIBID_QEMU_SOCKET");
    if (sock == nullptr || *sock == '\0') {
      bad("set VIBID_QEMU_SOCKET to the Unix socket the QEMU board image's USART1 is on");
    }
    spec.path = sock;
    return spec;
  }
  bad(kUsage);
  return spec;
}

std::vector<Listing> ListDevices() {
  std::vector<Listing> out;
  for (const HidListing& h : ListHidDevices()) {
    out.push_back(Listing{.spec = "hid:" + h.serial, .description = h.product + " at " + h.path});
  }
  try {
    for (const UsbipExport& e :
         ListUsbipExports(kDefaultUsbipHost, kDefaultUsbipPort, std::chrono::milliseconds(300))) {
      if (e.vendor_id != kUsbVendorId || e.product_id != kUsbProductId) continue;
      out.push_back(Listing{.spec = std::string("usbip://") + kDefaultUsbipHost + ":" +
                                    std::to_string(kDefaultUsbipPort),
                            .description = "USB/IP export " + e.busid});
    }
  } catch (const DeviceError&) {
    // No emulator listening: nothing to list there.
  }
  return out;
}

std::unique_ptr<Transport> OpenTransport(const DeviceSpec& spec) {
  switch (spec.kind) {
    case DeviceSpec::Kind::kHid: return OpenHid(spec.serial);
    case DeviceSpec::Kind::kUsbip: return UsbipDevice::Open(spec.host, spec.port);
    case DeviceSpec::Kind::kSerial: return OpenSerial(spec.path);
    case DeviceSpec::Kind::kAny: break;
  }
  const std::vector<Listing> all = ListDevices();
  if (all.empty())
    throw DeviceError(
        "no vibid device found (no board on USB HID, no vibid-emu on 127.0.0.1:3240)");
  if (all.size() > 1) {
    std::string names;
    for (const Listing& l : all) names += (names.empty() ? "" : ", ") + l.spec;
    throw DeviceError("several vibid devices found (" + names + "): choose one with --device");
  }
  return OpenTransport(ParseDeviceSpec(all[0].spec));
}

}  // namespace vibid::device
