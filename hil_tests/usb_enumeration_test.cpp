// Enumeration of the spawned emulator through the host's USB/IP client: the device list a USB/IP
// server answers, and the standard descriptors fetched with GET_DESCRIPTOR control transfers.
// Every field is decoded here from the byte layouts of the specifications (USB 2.0 §9.6,
// HID 1.11 §6.2, DFU 1.1 §4.1.3, Linux usbip_protocol.rst), not with the firmware's tables; the
// firmware's constants are only the expected identity (VID/PID, interface numbers).
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <map>
#include <thread>

#include "emulator_test.hpp"
#include "state_wait.hpp"
#include "vibid/device/usbip_transport.hpp"
#include "vibid/fw/usb/descriptors.hpp"
#include "vibid/shared/wire/report.hpp"

namespace vibid::hil {
namespace {

using device::GetDescriptor;
using device::Setup;
using device::UsbipDevice;

// Descriptor types, USB 2.0 table 9-5; HID 1.11 §7.1; DFU 1.1 §4.1.3.
constexpr std::uint8_t kDevice = 1, kConfiguration = 2, kString = 3, kInterface = 4, kEndpoint = 5;
constexpr std::uint8_t kHid = 0x21, kHidReport = 0x22, kDfuFunctional = 0x21;

std::uint16_t Le16(const std::vector<std::uint8_t>& d, std::size_t at) {
  return static_cast<std::uint16_t>(d.at(at) | (d.at(at + 1) << 8));
}

/// GET_DESCRIPTOR addressed to an interface (HID 1.11 §7.1.1: class descriptors).
std::vector<std::uint8_t> InterfaceDescriptor(UsbipDevice& usb, std::uint8_t type,
                                              std::uint8_t interface, std::uint16_t length) {
  Setup s;
  s.request_type = 0x81;  // device-to-host, standard, interface
  s.request = device::kGetDescriptor;
  s.value = static_cast<std::uint16_t>(type << 8);
  s.index = interface;
  s.length = length;
  return usb.Control(s, {}, std::chrono::milliseconds(1000));
}

/// A string descriptor decoded by hand: bLength, type 3, UTF-16LE code units (ASCII expected).
std::string StringAt(UsbipDevice& usb, std::uint8_t index) {
  const std::vector<std::uint8_t> d = GetDescriptor(usb, kString, index, 255, 0x0409);
  EXPECT_GE(d.size(), 2u);
  if (d.size() < 2) return {};
  EXPECT_EQ(d[0], d.size()) << "bLength of string " << int{index};
  EXPECT_EQ(d[1], kString);
  EXPECT_EQ(d.size() % 2, 0u) << "UTF-16 code units";
  std::string s;
  for (std::size_t i = 2; i + 1 < d.size(); i += 2) {
    EXPECT_EQ(d[i + 1], 0) << "non-ASCII code unit in string " << int{index};
    s.push_back(static_cast<char>(d[i]));
  }
  return s;
}

class UsbEnumerationTest : public EmulatorTest {
 protected:
  UsbEnumerationTest() : EmulatorTest("exposes no USB device to the test (USB/IP only)") {}

  void SetUpEmulator() override { usb = UsbipDevice::Open("127.0.0.1", emu->port()); }
  std::unique_ptr<UsbipDevice> usb;
};

TEST_F(UsbEnumerationTest, DeviceDescriptorFollowsUsb20Table9_8) {
  const std::vector<std::uint8_t> d = GetDescriptor(*usb, kDevice, 0, 18);
  ASSERT_EQ(d.size(), 18u);
  EXPECT_EQ(d[0], 18);            // bLength
  EXPECT_EQ(d[1], kDevice);       // bDescriptorType
  EXPECT_EQ(Le16(d, 2), 0x0200);  // bcdUSB 2.00
  EXPECT_EQ(d[4], 0);             // bDeviceClass: defined per interface
  EXPECT_EQ(d[7], 64);            // bMaxPacketSize0: 64 at full speed (§9.6.1)
  EXPECT_EQ(Le16(d, 8), fw::usb::kVendorId);
  EXPECT_EQ(Le16(d, 10), fw::usb::kProductId);
  EXPECT_EQ(Le16(d, 8), device::kUsbVendorId) << "the host's device filter";
  EXPECT_EQ(Le16(d, 10), device::kUsbProductId);
  EXPECT_NE(d[14], 0) << "iManufacturer";
  EXPECT_NE(d[15], 0) << "iProduct";
  EXPECT_NE(d[16], 0) << "iSerialNumber";
  EXPECT_EQ(d[17], 1);  // bNumConfigurations
  EXPECT_EQ(d, usb->device_descriptor()) << "what Open enumerated";
  // A shorter wLength returns the first bytes only (§9.4.3): the host's first 8-byte request.
  const std::vector<std::uint8_t> head = GetDescriptor(*usb, kDevice, 0, 8);
  EXPECT_EQ(head, std::vector<std::uint8_t>(d.begin(), d.begin() + 8));
}

TEST_F(UsbEnumerationTest, ConfigurationWalksToHidInterfaceAndDfuRuntimeInterface) {
  const std::vector<std::uint8_t> head = GetDescriptor(*usb, kConfiguration, 0, 9);
  ASSERT_EQ(head.size(), 9u);
  EXPECT_EQ(head[0], 9);
  EXPECT_EQ(head[1], kConfiguration);
  const std::uint16_t total = Le16(head, 2);
  const std::vector<std::uint8_t> cfg = GetDescriptor(*usb, kConfiguration, 0, 255);
  ASSERT_EQ(cfg.size(), total) << "wTotalLength is what a longer request returns";
  EXPECT_TRUE(std::equal(head.begin(), head.end(), cfg.begin()));
  EXPECT_EQ(head[5], 1) << "bConfigurationValue";
  EXPECT_NE(head[7] & 0x80, 0) << "bmAttributes bit 7 is reserved and set (§9.6.3)";

  // Walk the set: every descriptor's bLength fits its type, and they add up to wTotalLength.
  struct Interface {
    std::uint8_t number, cls, subclass, protocol, endpoints, name;
    int endpoints_seen = 0;
  };
  std::vector<Interface> interfaces;
  std::map<std::uint8_t, std::vector<std::uint8_t>> endpoints;  // address -> descriptor
  std::vector<std::uint8_t> hid, dfu;
  std::size_t at = 9;
  while (at < cfg.size()) {
    const std::uint8_t length = cfg[at];
    const std::uint8_t type = cfg.at(at + 1);
    ASSERT_GE(length, 2u) << "at " << at;
    ASSERT_LE(at + length, cfg.size()) << "descriptor at " << at << " runs past wTotalLength";
    const std::vector<std::uint8_t> d(cfg.begin() + static_cast<std::ptrdiff_t>(at),
                                      cfg.begin() + static_cast<std::ptrdiff_t>(at + length));
    if (type == kInterface) {
      ASSERT_EQ(length, 9);  // table 9-12
      interfaces.push_back({d[2], d[5], d[6], d[7], d[4], d[8]});
      EXPECT_EQ(d[3], 0) << "bAlternateSetting";
    } else if (type == kEndpoint) {
      ASSERT_EQ(length, 7);  // table 9-13
      ASSERT_FALSE(interfaces.empty());
      ++interfaces.back().endpoints_seen;
      endpoints[d[2]] = d;
    } else if (type == kHid && !interfaces.empty() && interfaces.back().cls == 0x03) {
      hid = d;
    } else if (type == kDfuFunctional && !interfaces.empty() && interfaces.back().cls == 0xFE) {
      dfu = d;
    } else {
      ADD_FAILURE() << "unexpected descriptor type " << int{type} << " at " << at;
    }
    at += length;
  }
  EXPECT_EQ(at, total);
  ASSERT_EQ(interfaces.size(), head[4]) << "bNumInterfaces";
  for (const Interface& i : interfaces)
    EXPECT_EQ(i.endpoints_seen, i.endpoints) << "interface " << int{i.number};

  // Interface 0: HID (class 3), no boot subclass, two interrupt endpoints of 64 bytes.
  ASSERT_EQ(interfaces.size(), 2u);
  EXPECT_EQ(interfaces[0].number, fw::usb::kHidInterface);
  EXPECT_EQ(interfaces[0].cls, 0x03);
  EXPECT_EQ(interfaces[0].subclass, 0);
  EXPECT_EQ(interfaces[0].protocol, 0);
  for (const std::uint8_t address : {std::uint8_t{0x81}, std::uint8_t{0x01}}) {
    ASSERT_EQ(endpoints.count(address), 1u) << "endpoint 0x" << std::hex << int{address};
    const std::vector<std::uint8_t>& e = endpoints[address];
    EXPECT_EQ(e[3] & 0x03, 0x03) << "bmAttributes: interrupt";
    EXPECT_EQ(Le16(e, 4), wire::kReportBytes)
        << "wMaxPacketSize: one 64-byte report per transaction";
    EXPECT_GE(e[6], 1) << "bInterval";
  }
  // HID 1.11 §6.2.1: bcdHID 1.11, one class descriptor of type Report.
  ASSERT_EQ(hid.size(), 9u);
  EXPECT_EQ(Le16(hid, 2), 0x0111);
  EXPECT_EQ(hid[5], 1);
  EXPECT_EQ(hid[6], kHidReport);
  // The HID descriptor alone, asked of the interface, is the same bytes (§7.1.1).
  EXPECT_EQ(InterfaceDescriptor(*usb, kHid, 0, 9), hid);

  // Interface 1: DFU run-time (application specific 0xFE, subclass 1, protocol 1 = run-time).
  EXPECT_EQ(interfaces[1].number, fw::usb::kDfuInterface);
  EXPECT_EQ(interfaces[1].cls, 0xFE);
  EXPECT_EQ(interfaces[1].subclass, 0x01);
  EXPECT_EQ(interfaces[1].protocol, 0x01);
  EXPECT_EQ(interfaces[1].endpoints, 0);
  ASSERT_EQ(dfu.size(), 9u) << "DFU 1.1 table 4.2";
  EXPECT_NE(dfu[2] & 0x08, 0) << "bitWillDetach: the board leaves for its bootloader by itself";
  EXPECT_NE(dfu[2] & 0x01, 0) << "bitCanDnload";
  EXPECT_EQ(Le16(dfu, 5), 2048) << "wTransferSize: the STM32 DfuSe bootloader's (AN3156)";
  EXPECT_EQ(Le16(dfu, 7), 0x0110) << "bcdDFUVersion 1.1";
  EXPECT_EQ(StringAt(*usb, interfaces[1].name), fw::usb::kDfuInterfaceName);
}

// HID 1.11 §6.2.2.2 short items: bSize in bits 0-1 (0, 1, 2 or 4 bytes), bType in 2-3, bTag in 4-7.
TEST_F(UsbEnumerationTest, HidReportDescriptorDeclares64ByteVendorReports) {
  const std::vector<std::uint8_t> hid = InterfaceDescriptor(*usb, kHid, 0, 9);
  ASSERT_EQ(hid.size(), 9u);
  const std::vector<std::uint8_t> r = InterfaceDescriptor(*usb, kHidReport, 0, 255);
  ASSERT_EQ(r.size(), Le16(hid, 7)) << "wDescriptorLength of the HID descriptor";
  std::uint32_t usage_page = 0, report_size = 0, report_count = 0;
  std::uint32_t input_bits = 0, output_bits = 0;
  int depth = 0, collections = 0;
  for (std::size_t i = 0; i < r.size();) {
    const std::uint8_t prefix = r[i];
    ASSERT_NE(prefix, 0xFE) << "long items are not expected";
    const std::size_t size = (prefix & 3) == 3 ? 4 : (prefix & 3);
    ASSERT_LE(i + 1 + size, r.size()) << "item at " << i << " runs past the descriptor";
    std::uint32_t data = 0;
    for (std::size_t k = 0; k < size; ++k) data |= std::uint32_t{r[i + 1 + k]} << (8 * k);
    switch (prefix & 0xFC) {
      case 0x04: usage_page = data; break;                          // Global: Usage Page
      case 0x74: report_size = data; break;                         // Global: Report Size
      case 0x94: report_count = data; break;                        // Global: Report Count
      case 0x80: input_bits += report_size * report_count; break;   // Main: Input
      case 0x90: output_bits += report_size * report_count; break;  // Main: Output
      case 0xA0: ++depth, ++collections; break;                     // Main: Collection
      case 0xC0: --depth; break;                                    // Main: End Collection
      default: break;
    }
    ASSERT_GE(depth, 0) << "End Collection without a Collection at " << i;
    i += 1 + size;
  }
  EXPECT_EQ(depth, 0) << "collections balanced";
  EXPECT_EQ(collections, 1);
  EXPECT_EQ(usage_page, 0xFF00u) << "vendor-defined page";
  EXPECT_EQ(usage_page, wire::kHidUsagePage) << "what the host's hidapi filter looks for";
  EXPECT_EQ(input_bits, 8u * wire::kReportBytes);
  EXPECT_EQ(output_bits, 8u * wire::kReportBytes);
}

TEST_F(UsbEnumerationTest, StringDescriptorsNameTheBoardAndItsSerial) {
  // String 0: the LANGID table (§9.6.7), US English only.
  const std::vector<std::uint8_t> langs = GetDescriptor(*usb, kString, 0, 255);
  ASSERT_EQ(langs.size(), 4u);
  EXPECT_EQ(langs[0], 4);
  EXPECT_EQ(langs[1], kString);
  EXPECT_EQ(Le16(langs, 2), 0x0409);
  const std::vector<std::uint8_t>& dev = usb->device_descriptor();
  EXPECT_EQ(StringAt(*usb, dev[14]), "vibid");
  EXPECT_EQ(StringAt(*usb, dev[15]), "vibid DAQ");
  // The serial is the one the emulator announced on its first line ("serial EMU...").
  const std::string serial = StringAt(*usb, dev[16]);
  EXPECT_EQ(serial.rfind("EMU", 0), 0u) << serial;
  EXPECT_NE(emu->banner().find("serial " + serial + ","), std::string::npos) << emu->banner();
  EXPECT_EQ(device::GetStringDescriptor(*usb, dev[16]), serial) << "the host library's decoding";
}

/// OP_REQ_DEVLIST on a plain socket, decoded from usbip_protocol.rst: 8-byte reply header
/// (version, code 0x0005, status), u32 device count, per device a 312-byte usbip_usb_device
/// (path[256], busid[32], busnum, devnum, speed, idVendor, idProduct, bcdDevice, 6 class and count
/// bytes) and 4 bytes per interface. Network byte order.
struct RawExport {
  std::string busid;
  std::uint32_t speed = 0;
  std::uint16_t vendor = 0, product = 0;
  std::vector<std::array<std::uint8_t, 3>> interfaces;
};

std::vector<RawExport> RawDeviceList(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (fd < 0 || ::connect(fd, reinterpret_cast<const sockaddr*>(&a), sizeof(a)) != 0) {
    ADD_FAILURE() << "cannot connect";
    return {};
  }
  const std::uint8_t request[8] = {0x01, 0x11, 0x80, 0x05, 0, 0, 0, 0};
  EXPECT_EQ(::write(fd, request, sizeof(request)), 8);
  std::vector<std::uint8_t> reply;
  std::uint8_t buf[4096];
  for (ssize_t n; (n = ::read(fd, buf, sizeof(buf))) > 0;) reply.insert(reply.end(), buf, buf + n);
  ::close(fd);
  const auto be16 = [&](std::size_t at) {
    return static_cast<std::uint16_t>((reply.at(at) << 8) | reply.at(at + 1));
  };
  const auto be32 = [&](std::size_t at) { return (std::uint32_t{be16(at)} << 16) | be16(at + 2); };
  std::vector<RawExport> out;
  EXPECT_GE(reply.size(), 12u);
  if (reply.size() < 12) return out;
  EXPECT_EQ(be16(0), 0x0111) << "USB/IP version 1.1.1";
  EXPECT_EQ(be16(2), 0x0005) << "OP_REP_DEVLIST";
  EXPECT_EQ(be32(4), 0u) << "status";
  std::size_t at = 12;
  for (std::uint32_t i = 0; i < be32(8); ++i) {
    RawExport e;
    e.busid = std::string(reinterpret_cast<const char*>(&reply.at(at + 256)));
    e.speed = be32(at + 296);
    e.vendor = be16(at + 300);
    e.product = be16(at + 302);
    const std::uint8_t n = reply.at(at + 311);
    at += 312;
    for (std::uint8_t k = 0; k < n; ++k, at += 4)
      e.interfaces.push_back({reply.at(at), reply.at(at + 1), reply.at(at + 2)});
    out.push_back(e);
  }
  EXPECT_EQ(at, reply.size()) << "nothing after the last device";
  return out;
}

TEST_F(UsbEnumerationTest, DeviceListNamesBusIdIdsAndInterfaceClasses) {
  usb.reset();  // released: listed, and importable again below
  const std::vector<RawExport> raw = RawDeviceList(emu->port());
  ASSERT_EQ(raw.size(), 1u);
  EXPECT_EQ(raw[0].busid, "1-1");
  EXPECT_EQ(raw[0].speed, 2u) << "USB_SPEED_FULL (linux/usb/ch9.h)";
  EXPECT_EQ(raw[0].vendor, fw::usb::kVendorId);
  EXPECT_EQ(raw[0].product, fw::usb::kProductId);
  ASSERT_EQ(raw[0].interfaces.size(), 2u);
  EXPECT_EQ(raw[0].interfaces[0], (std::array<std::uint8_t, 3>{0x03, 0x00, 0x00}));  // HID
  EXPECT_EQ(raw[0].interfaces[1], (std::array<std::uint8_t, 3>{0xFE, 0x01, 0x01}));  // DFU run-time

  // The host library reads the same list.
  const std::vector<device::UsbipExport> listed =
      device::ListUsbipExports("127.0.0.1", emu->port());
  ASSERT_EQ(listed.size(), 1u);
  EXPECT_EQ(listed[0].busid, raw[0].busid);
  EXPECT_EQ(listed[0].vendor_id, raw[0].vendor);
  EXPECT_EQ(listed[0].product_id, raw[0].product);
  ASSERT_EQ(listed[0].interface_classes.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(listed[0].interface_classes[i].interface_class, raw[0].interfaces[i][0]);
    EXPECT_EQ(listed[0].interface_classes[i].interface_subclass, raw[0].interfaces[i][1]);
    EXPECT_EQ(listed[0].interface_classes[i].interface_protocol, raw[0].interfaces[i][2]);
  }
  // The release above is a closed socket, which the server notices on its own schedule: until
  // then it refuses the import as busy, as usbipd does. It must export again (a state waited
  // for; how soon is not this test's to judge).
  const auto deadline = std::chrono::steady_clock::now() + hil::kStateWait;
  for (;;) {
    try {
      usb = UsbipDevice::Open("127.0.0.1", emu->port());
      break;
    } catch (const device::DeviceError& e) {
      ASSERT_LT(std::chrono::steady_clock::now(), deadline)
          << "waited " << hil::kStateWait.count() << " s for the export again: " << e.what();
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
}

}  // namespace
}  // namespace vibid::hil
