// Descriptor bytes as the host reads them with GET_DESCRIPTOR, checked against expectations
// decoded by hand from USB 2.0 §9.6 (tables 9-8, 9-10, 9-12, 9-13), HID 1.11 §6.2 and
// DFU 1.1 §4.1.3. The expected arrays are written out field by field here, not derived from the
// firmware's constants, so a changed descriptor fails until someone re-decodes it.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>

#include "usb_test_host.hpp"

namespace vibid::fw::usb {
namespace {

using testing::Rig;

template <std::size_t N>
void ExpectBytes(std::span<const std::uint8_t> got, const std::array<std::uint8_t, N>& want) {
  ASSERT_EQ(got.size(), N);
  for (std::size_t i = 0; i < N; ++i) EXPECT_EQ(got[i], want[i]);
}

TEST(UsbDescriptors, DeviceDescriptor) {
  Rig rig;
  rig.host.BusReset();
  // GET_DESCRIPTOR(DEVICE), wLength 18 (USB 2.0 §9.4.3).
  const auto r = rig.host.Control({0x80, 0x06, 0x00, 0x01, 0x00, 0x00, 0x12, 0x00});
  ASSERT_FALSE(r.stalled);
  ASSERT_FALSE(r.protocol_error);
  const std::array<std::uint8_t, 18> want = {
      0x12,        // bLength 18
      0x01,        // bDescriptorType DEVICE
      0x00, 0x02,  // bcdUSB 2.00
      0x00,        // bDeviceClass: defined by the interfaces
      0x00,        // bDeviceSubClass
      0x00,        // bDeviceProtocol
      0x40,        // bMaxPacketSize0 64
      0x09, 0x12,  // idVendor 0x1209 (pid.codes)
      0x01, 0x00,  // idProduct 0x0001
      0x10, 0x00,  // bcdDevice 0.10
      0x01,        // iManufacturer -> string 1
      0x02,        // iProduct -> string 2
      0x03,        // iSerialNumber -> string 3
      0x01,        // bNumConfigurations 1
  };
  ExpectBytes(r.Bytes(), want);
}

TEST(UsbDescriptors, ConfigurationDescriptorSet) {
  Rig rig;
  rig.host.BusReset();
  // Windows and Linux first read the 9-byte header, then wTotalLength (Windows asks for 255).
  const auto header = rig.host.Control({0x80, 0x06, 0x00, 0x02, 0x00, 0x00, 0x09, 0x00});
  ASSERT_EQ(header.length, 9U);
  EXPECT_EQ(header.data[2], 59);  // wTotalLength low byte
  const auto r = rig.host.Control({0x80, 0x06, 0x00, 0x02, 0x00, 0x00, 0xFF, 0x00});
  ASSERT_FALSE(r.stalled);
  EXPECT_EQ(r.packets, 1U);  // 59 < 64: one short packet ends the data stage, no ZLP
  const std::array<std::uint8_t, 59> want = {
      // Configuration (table 9-10)
      0x09,        // bLength
      0x02,        // bDescriptorType CONFIGURATION
      0x3B, 0x00,  // wTotalLength 59
      0x02,        // bNumInterfaces: HID + DFU run-time
      0x01,        // bConfigurationValue
      0x00,        // iConfiguration: none
      0x80,        // bmAttributes: reserved bit 7 set, bus powered, no remote wakeup
      0x7D,        // bMaxPower 125 x 2 mA = 250 mA
      // Interface 0 (table 9-12)
      0x09,  // bLength
      0x04,  // bDescriptorType INTERFACE
      0x00,  // bInterfaceNumber 0
      0x00,  // bAlternateSetting 0
      0x02,  // bNumEndpoints 2
      0x03,  // bInterfaceClass HID
      0x00,  // bInterfaceSubClass: no boot interface
      0x00,  // bInterfaceProtocol: none
      0x00,  // iInterface
      // HID descriptor (HID 1.11 §6.2.1)
      0x09,        // bLength
      0x21,        // bDescriptorType HID
      0x11, 0x01,  // bcdHID 1.11
      0x00,        // bCountryCode: not localized
      0x01,        // bNumDescriptors
      0x22,        // bDescriptorType REPORT
      0x19, 0x00,  // wDescriptorLength 25
      // Endpoint (table 9-13)
      0x07,        // bLength
      0x05,        // bDescriptorType ENDPOINT
      0x81,        // bEndpointAddress 1 IN
      0x03,        // bmAttributes interrupt
      0x40, 0x00,  // wMaxPacketSize 64
      0x01,        // bInterval 1 frame (1 ms)
      0x07,        // bLength
      0x05,        // bDescriptorType ENDPOINT
      0x01,        // bEndpointAddress 1 OUT
      0x03,        // bmAttributes interrupt
      0x40, 0x00,  // wMaxPacketSize 64
      0x01,        // bInterval 1 frame
      // Interface 1: DFU run-time (DFU 1.1 table 4.1)
      0x09,  // bLength
      0x04,  // bDescriptorType INTERFACE
      0x01,  // bInterfaceNumber 1
      0x00,  // bAlternateSetting 0
      0x00,  // bNumEndpoints 0 (control pipe only)
      0xFE,  // bInterfaceClass application specific
      0x01,  // bInterfaceSubClass device firmware upgrade
      0x01,  // bInterfaceProtocol run-time
      0x04,  // iInterface -> string 4
      // DFU functional descriptor (DFU 1.1 table 4.2)
      0x09,        // bLength
      0x21,        // bDescriptorType DFU FUNCTIONAL
      0x0B,        // bmAttributes: bitWillDetach | bitCanUpload | bitCanDnload
      0xE8, 0x03,  // wDetachTimeOut 1000 ms
      0x00, 0x08,  // wTransferSize 2048
      0x10, 0x01,  // bcdDFUVersion 1.1
  };
  ExpectBytes(r.Bytes(), want);
}

TEST(UsbDescriptors, ConfigurationWalksAsDescriptorChain) {
  Rig rig;
  rig.host.BusReset();
  const auto r = rig.host.Control({0x80, 0x06, 0x00, 0x02, 0x00, 0x00, 0xFF, 0x00});
  // Every descriptor's bLength leads exactly to the next one and the chain ends at wTotalLength.
  std::size_t at = 0;
  int count = 0;
  while (at < r.length) {
    ASSERT_GE(r.data[at], 2);
    at += r.data[at];
    ++count;
  }
  EXPECT_EQ(at, r.length);
  EXPECT_EQ(count, 7);
}

TEST(UsbDescriptors, HidReportDescriptor) {
  Rig rig;
  rig.host.Enumerate(7);
  // HID 1.11 §7.1.1: GET_DESCRIPTOR to the interface, wValue high byte 0x22 (report), wLength as
  // the HID descriptor announced (25).
  const auto r = rig.host.Control({0x81, 0x06, 0x00, 0x22, 0x00, 0x00, 0x19, 0x00});
  ASSERT_FALSE(r.stalled);
  const std::array<std::uint8_t, 25> want = {
      0x06, 0x00, 0xFF,  // Usage Page (global, 2 bytes): 0xFF00 vendor defined
      0x09, 0x01,        // Usage (local): 1
      0xA1, 0x01,        // Collection: Application
      0x15, 0x00,        // Logical Minimum 0
      0x26, 0xFF, 0x00,  // Logical Maximum 255 (2 bytes so it is not read as -1)
      0x75, 0x08,        // Report Size 8 bits
      0x95, 0x40,        // Report Count 64 -> 64-byte reports, no Report ID item anywhere
      0x09, 0x02,        // Usage 2
      0x81, 0x02,        // Input: Data, Variable, Absolute
      0x09, 0x03,        // Usage 3
      0x91, 0x02,        // Output: Data, Variable, Absolute
      0xC0,              // End Collection
  };
  ExpectBytes(r.Bytes(), want);

  // The HID descriptor alone: wValue high byte 0x21.
  const auto hid = rig.host.Control({0x81, 0x06, 0x00, 0x21, 0x00, 0x00, 0x09, 0x00});
  const std::array<std::uint8_t, 9> want_hid = {0x09, 0x21, 0x11, 0x01, 0x00,
                                                0x01, 0x22, 0x19, 0x00};
  ExpectBytes(hid.Bytes(), want_hid);
}

TEST(UsbDescriptors, StringDescriptors) {
  Rig rig;
  rig.host.BusReset();
  // String 0: the LANGID table (USB 2.0 table 9-15), one language 0x0409 English (US).
  const auto langs = rig.host.Control({0x80, 0x06, 0x00, 0x03, 0x00, 0x00, 0xFF, 0x00});
  const std::array<std::uint8_t, 4> want_langs = {0x04, 0x03, 0x09, 0x04};
  ExpectBytes(langs.Bytes(), want_langs);

  // String 1 "vibid" in UTF-16LE: bLength 2 + 2 x 5 = 12.
  const auto maker = rig.host.Control({0x80, 0x06, 0x01, 0x03, 0x09, 0x04, 0xFF, 0x00});
  const std::array<std::uint8_t, 12> want_maker = {0x0C, 0x03, 'v', 0, 'i', 0,
                                                   'b',  0,    'i', 0, 'd', 0};
  ExpectBytes(maker.Bytes(), want_maker);

  // String 3, the serial: 24 hex digits -> bLength 50; the digits are the board id as given.
  const auto serial = rig.host.Control({0x80, 0x06, 0x03, 0x03, 0x09, 0x04, 0xFF, 0x00});
  ASSERT_EQ(serial.length, 50U);
  EXPECT_EQ(serial.data[0], 50);
  EXPECT_EQ(serial.data[1], 0x03);
  for (std::size_t i = 0; i < 24; ++i) {
    EXPECT_EQ(serial.data[2 + 2 * i], static_cast<std::uint8_t>(Rig::kSerial[i]));
    EXPECT_EQ(serial.data[3 + 2 * i], 0);
  }

  // No string 5.
  EXPECT_TRUE(rig.host.Control({0x80, 0x06, 0x05, 0x03, 0x09, 0x04, 0xFF, 0x00}).stalled);
}

TEST(UsbDescriptors, StringOfExactlyOnePacketEndsWithZeroLengthPacket) {
  // A 31-character serial gives a 64-byte descriptor. Asked with wLength 255 the device must send
  // one full packet and then a ZLP, or the host waits for more (USB 2.0 §5.5.3); asked with
  // wLength 64 it must not send the ZLP.
  Rig rig{"ABCDEFGHIJKLMNOPQRSTUVWXYZ01234"};
  ASSERT_EQ(rig.start_status, Status::kOk);
  rig.host.BusReset();
  const auto with_zlp = rig.host.Control({0x80, 0x06, 0x03, 0x03, 0x09, 0x04, 0xFF, 0x00});
  ASSERT_FALSE(with_zlp.protocol_error);
  EXPECT_EQ(with_zlp.length, 64U);
  EXPECT_EQ(with_zlp.packets, 2U);
  const auto exact = rig.host.Control({0x80, 0x06, 0x03, 0x03, 0x09, 0x04, 0x40, 0x00});
  ASSERT_FALSE(exact.protocol_error);
  EXPECT_EQ(exact.length, 64U);
  EXPECT_EQ(exact.packets, 1U);
}

}  // namespace
}  // namespace vibid::fw::usb
