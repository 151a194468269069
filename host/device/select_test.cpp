#include "vibid/device/select.hpp"

#include <gtest/gtest.h>

#include <cstdlib>

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

TEST(ChooseDevice, TheOptionWinsOverTheVariable) {
  ::unsetenv("VIBID_DEVICE");
  EXPECT_EQ(ChooseDevice("").text, "");
  EXPECT_EQ(ChooseDevice("hid").origin, "--device");
  ::setenv("VIBID_DEVICE", "usbip://127.0.0.1:3250", 1);
  const DeviceChoice from_variable = ChooseDevice("");
  EXPECT_EQ(from_variable.text, "usbip://127.0.0.1:3250");
  EXPECT_EQ(from_variable.origin, "VIBID_DEVICE");
  const DeviceChoice from_option = ChooseDevice("hid:0042A1");
  EXPECT_EQ(from_option.text, "hid:0042A1");
  EXPECT_EQ(from_option.origin, "--device");
  ::setenv("VIBID_DEVICE", "", 1);  // set but empty: as if unset
  EXPECT_EQ(ChooseDevice("").origin, "");
  ::unsetenv("VIBID_DEVICE");
  // A malformed value is named with where it came from.
  try {
    ParseDeviceSpec("tcp://h", "VIBID_DEVICE");
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "VIBID_DEVICE 'tcp://h': expected hid[:SERIAL], usbip://HOST[:PORT], serial:PATH or "
              "qemu");
  }
}

}  // namespace
}  // namespace vibid::device
