// vibid flash IMAGE.bin: the application asks the board into its DfuSe bootloader (enter-DFU), the
// host erases the sectors the image covers, downloads it, reads it back byte for byte and leaves
// the bootloader, which starts the new firmware.
#include <chrono>
#include <cstdlib>
#include <iostream>
#include <thread>

#include "cli_support.hpp"
#include "device_commands.hpp"
#include "session.hpp"
#include "vibid/common/atomic_file.hpp"
#include "vibid/common/error.hpp"
#include "vibid/device/dfuse.hpp"
#include "vibid/device/error.hpp"
#include "vibid/device/libusb_control.hpp"
#include "vibid/device/select.hpp"
#include "vibid/device/usbip_transport.hpp"

namespace vibid::cli {
namespace {

constexpr std::uint32_t kFlashBase = 0x08000000u;
constexpr auto kReenumerationTimeout = std::chrono::seconds(10);

/// Retries `open` until the bootloader has enumerated (the board needs a moment to re-attach).
template <typename Open>
auto AwaitBootloader(Open open) {
  const auto deadline = std::chrono::steady_clock::now() + kReenumerationTimeout;
  for (;;) {
    try {
      return open();
    } catch (const device::DeviceError&) {
      if (std::chrono::steady_clock::now() > deadline) throw;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }
}

struct FlashOptions {
  std::string image;
  std::string address = "0x08000000";
};

}  // namespace

void RegisterFlashCommand(CLI::App& app, const GlobalOptions& globals) {
  CLI::App* flash = app.add_subcommand("flash", "Write a firmware image through the DfuSe bootloader and verify it");
  auto o = std::make_shared<FlashOptions>();
  flash->add_option("image", o->image, "Raw image (.bin)")->required();
  flash->add_option("--address", o->address, "Flash address of the image's first byte")->capture_default_str();
  flash->callback([&globals, o] {
    const std::string text = ReadFileText(o->image);
    const std::vector<std::uint8_t> image(text.begin(), text.end());
    Require(!image.empty(), o->image + ": the image is empty");
    char* end = nullptr;
    const unsigned long long address = std::strtoull(o->address.c_str(), &end, 0);
    Require(!o->address.empty() && *end == '\0' && address >= kFlashBase && address <= 0xFFFFFFFFull,
            "--address '" + o->address + "' must be a flash address from 0x08000000");
    device::DeviceSpec spec = device::ParseDeviceSpec(globals.device);
    try {
      if (spec.kind == device::DeviceSpec::Kind::kAny) {
        const auto all = device::ListDevices();
        if (all.size() == 1) spec = device::ParseDeviceSpec(all[0].spec);
      }
      Require(spec.kind != device::DeviceSpec::Kind::kSerial, "the QEMU image has no bootloader: flash needs hid or usbip");
      // The application, if it runs, enters the bootloader; a board already in DFU goes straight on.
      try {
        device::Connection c(device::OpenTransport(spec));
        if ((c.info().capabilities & wire::kCapDfu) == 0) throw DeviceError("this board cannot enter DFU");
        static_cast<void>(c.Expect(wire::Command::kEnterDfu));
        std::cerr << "vibid: board entered its bootloader\n";
      } catch (const device::DeviceError& e) {
        std::cerr << "vibid: no running application (" << e.what() << "); looking for a bootloader\n";
      }
      ProgressBar erase("erase"), download("download"), verify("verify");
      const device::FlashProgress progress = [&](const std::string& phase, std::uint64_t done, std::uint64_t total) {
        (phase == "erase" ? erase : phase == "download" ? download : verify).Update(done, total);
      };
      std::vector<device::DfuSeSector> layout;
      if (spec.kind == device::DeviceSpec::Kind::kUsbip) {
        auto usb = AwaitBootloader([&] {
          return device::UsbipDevice::Open(spec.host, spec.port, {}, device::kDfuSeVendorId, device::kDfuSeProductId);
        });
        device::DfuSe dfu = device::DfuSe::Open(*usb, layout);
        device::FlashImage(dfu, layout, image, static_cast<std::uint32_t>(address), progress);
      } else {
        auto usb = AwaitBootloader([&] {
          return device::OpenLibusbControl(device::kDfuSeVendorId, device::kDfuSeProductId, 0);
        });
        device::DfuSe dfu = device::DfuSe::Open(*usb, layout);
        device::FlashImage(dfu, layout, image, static_cast<std::uint32_t>(address), progress);
      }
    } catch (const device::DeviceError& e) {
      throw DeviceError(e.what());
    }
    std::cout << "flashed " << image.size() << " bytes at " << o->address << ", verified; the board restarts\n";
  });
}

}  // namespace vibid::cli
