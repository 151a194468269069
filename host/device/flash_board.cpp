#include "vibid/device/flash_board.hpp"

#include <chrono>
#include <memory>
#include <thread>

#include "vibid/common/error.hpp"
#include "vibid/device/connection.hpp"
#include "vibid/device/error.hpp"
#include "vibid/device/libusb_control.hpp"
#include "vibid/device/usbip_transport.hpp"

namespace vibid::device {
namespace {

constexpr auto kReenumerationTimeout = std::chrono::seconds(10);

/// Retries `open` until the bootloader has enumerated (the board needs a moment to re-attach).
template <typename Open>
auto AwaitBootloader(Open open) {
  const auto deadline = std::chrono::steady_clock::now() + kReenumerationTimeout;
  for (;;) {
    try {
      return open();
    } catch (const DeviceError&) {
      if (std::chrono::steady_clock::now() > deadline) throw;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }
}

}  // namespace

FlashBoardResult FlashBoard(DeviceSpec spec, std::span<const std::uint8_t> image,
                            std::uint32_t address, const FlashProgress& progress,
                            const std::function<void(const std::string&)>& note) {
  const std::span<const FlashRange> keep(&kCalibrationSectors, 1);
  FlashBoardResult result;
  // Planned from the layout the bootloader will report, before the board is asked into DFU.
  result.plan = PlanFlash(ParseDfuSeLayout(dfu::kStm32f405FlashLayout), image, address, keep);
  if (spec.kind == DeviceSpec::Kind::kAny) {
    const auto all = ListDevices();
    if (all.size() == 1) spec = ParseDeviceSpec(all[0].spec);
  }
  if (spec.kind == DeviceSpec::Kind::kSerial)
    throw InputError("a serial link has no bootloader: flash needs hid or usbip");
  // The application, if it runs, enters the bootloader; a board already in DFU goes straight on.
  try {
    Connection c(OpenTransport(spec));
    if ((c.info().capabilities & wire::kCapDfu) == 0)
      throw DeviceError("this board cannot enter DFU");
    static_cast<void>(c.Expect(wire::Command::kEnterDfu));
    result.from_application = true;
    if (note) note("board entered its bootloader");
  } catch (const DeviceError& e) {
    if (note)
      note(std::string("no running application (") + e.what() + "); looking for a bootloader");
  }
  const std::unique_ptr<UsbControl> usb = AwaitBootloader([&]() -> std::unique_ptr<UsbControl> {
    if (spec.kind == DeviceSpec::Kind::kUsbip) {
      return UsbipDevice::Open(spec.host, spec.port, {}, dfu::kStBootloaderVendorId,
                               dfu::kStBootloaderProductId);
    }
    return OpenLibusbControl(dfu::kStBootloaderVendorId, dfu::kStBootloaderProductId, 0);
  });
  std::vector<DfuSeSector> layout;
  DfuSe dfu = DfuSe::Open(*usb, layout);
  FlashImage(dfu, layout, image, address, keep, progress);
  return result;
}

}  // namespace vibid::device
