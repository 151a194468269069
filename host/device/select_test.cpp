#include "vibid/device/select.hpp"

#include <gtest/gtest.h>

#include "vibid/common/error.hpp"

namespace vibid::device {
namespace {

TEST(ParseDeviceSpec, ReadsEveryForm) {
  EXPECT_EQ(ParseDeviceSpec("").kind, DeviceSpec::Kind::kAny);
  const DeviceSpec hid = ParseDeviceSpec("hid");
  EXPECT_EQ(hid.kind, DeviceSpec::Kind::kHid);
  EXPECT_EQ(hid.serial, "");
  EXPECT_EQ(ParseDeviceSpec("hid:0042A1").serial, "0042A1");
  const DeviceSpec u = ParseDeviceSpec("usbip://127.0.0.1:3250");
  EXPECT_EQ(u.kind, DeviceSpec::Kind::kUsbip);
  EXPECT_EQ(u.host, "127.0.0.1");
  EXPECT_EQ(u.port, 3250);
  const DeviceSpec d = ParseDeviceSpec("usbip://emu.local");
  EXPECT_EQ(d.host, "emu.local");
  EXPECT_EQ(d.port, 3240);  // the USB/IP default port
  const DeviceSpec s = ParseDeviceSpec("serial:/dev/ttyUSB0");
  EXPECT_EQ(s.kind, DeviceSpec::Kind::kSerial);
  EXPECT_EQ(s.path, "/dev/ttyUSB0");
}

TEST(ParseDeviceSpec, RefusesMalformedValuesNamingThem) {
  for (const char* bad : {"hid:", "usbip://", "usbip://h:0", "usbip://h:70000", "usbip://h:x",
                          "tcp://h", "HID", "serial:"}) {
    try {
      ParseDeviceSpec(bad);
      ADD_FAILURE() << bad << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("'") + bad + "'"), std::string::npos)
          << e.what();
    }
  }
}

}  // namespace
}  // namespace vibid::device
