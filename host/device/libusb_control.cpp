#include "vibid/device/libusb_control.hpp"

#include <libusb.h>

#include <cstdio>
#include <string>

#include "vibid/device/error.hpp"

namespace vibid::device {
namespace {

class LibusbControl final : public UsbControl {
 public:
  LibusbControl(libusb_context* ctx, libusb_device_handle* h, std::uint8_t interface)
      : ctx_(ctx), handle_(h), interface_(interface) {}
  ~LibusbControl() override {
    libusb_release_interface(handle_, interface_);
    libusb_close(handle_);
    libusb_exit(ctx_);
  }
  LibusbControl(const LibusbControl&) = delete;
  LibusbControl& operator=(const LibusbControl&) = delete;

  std::vector<std::uint8_t> Control(const Setup& s, std::span<const std::uint8_t> out,
                                    std::chrono::milliseconds timeout) override {
    std::vector<std::uint8_t> buf(s.In() ? s.length : out.size());
    if (!s.In()) std::copy(out.begin(), out.end(), buf.begin());
    const int n = libusb_control_transfer(handle_, s.request_type, s.request, s.value, s.index,
                                          buf.data(), static_cast<std::uint16_t>(buf.size()),
                                          static_cast<unsigned>(timeout.count()));
    if (n < 0) {
      throw DeviceError("USB control request " + std::to_string(s.request) +
                        " failed: " + libusb_error_name(n));
    }
    if (!s.In()) return {};
    buf.resize(static_cast<std::size_t>(n));
    return buf;
  }

 private:
  libusb_context* ctx_;
  libusb_device_handle* handle_;
  std::uint8_t interface_;
};

}  // namespace

std::unique_ptr<UsbControl> OpenLibusbControl(std::uint16_t vendor_id, std::uint16_t product_id,
                                              std::uint8_t interface) {
  libusb_context* ctx = nullptr;
  if (libusb_init(&ctx) != 0) throw DeviceError("libusb could not be initialised");
  libusb_device_handle* h = libusb_open_device_with_vid_pid(ctx, vendor_id, product_id);
  if (h == nullptr) {
    libusb_exit(ctx);
    char id[10];
    std::snprintf(id, sizeof(id), "%04x:%04x", vendor_id, product_id);
    throw DeviceError(std::string("no USB device ") + id +
                      " (is the board in DFU mode? permissions?)");
  }
  const int r = libusb_claim_interface(h, interface);
  if (r != 0) {
    libusb_close(h);
    libusb_exit(ctx);
    throw DeviceError(std::string("cannot claim the DFU interface: ") + libusb_error_name(r));
  }
  return std::make_unique<LibusbControl>(ctx, h, interface);
}

}  // namespace vibid::device
