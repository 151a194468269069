#include "vibid/device/hid_transport.hpp"

#include <hidapi.h>

#include <algorithm>
#include <mutex>

#include "vibid/device/error.hpp"

namespace vibid::device {
namespace {

std::string Narrow(const wchar_t* w) {
  std::string s;
  if (w == nullptr) return s;
  for (; *w != 0; ++w) s.push_back(*w < 0x80 ? static_cast<char>(*w) : '?');
  return s;
}

void InitHidapi() {
  static std::once_flag once;
  static int result = 0;
  std::call_once(once, [] { result = hid_init(); });
  if (result != 0) throw DeviceError("hidapi could not be initialised");
}

class HidTransport final : public Transport {
 public:
  HidTransport(hid_device* handle, HidListing listing)
      : handle_(handle), listing_(std::move(listing)) {}
  ~HidTransport() override { hid_close(handle_); }
  HidTransport(const HidTransport&) = delete;
  HidTransport& operator=(const HidTransport&) = delete;

  void Send(const wire::Report& report) override {
    // No report ids: hidapi wants a leading 0 byte that is not sent.
    std::array<unsigned char, wire::kReportBytes + 1> buf{};
    std::copy(report.begin(), report.end(), buf.begin() + 1);
    if (hid_write(handle_, buf.data(), buf.size()) < 0) {
      throw DeviceError("HID write failed: " + Narrow(hid_error(handle_)));
    }
  }

  std::size_t Receive(std::span<std::uint8_t, wire::kReportBytes> out,
                      std::chrono::milliseconds timeout) override {
    const int n =
        hid_read_timeout(handle_, out.data(), out.size(), static_cast<int>(timeout.count()));
    if (n < 0) throw DeviceError("HID read failed: " + Narrow(hid_error(handle_)));
    return static_cast<std::size_t>(n);
  }

  std::string SerialNumber() const override { return listing_.serial; }

  std::string Describe() const override {
    return "hid:" + listing_.serial + " (" + listing_.path + ")";
  }

 private:
  hid_device* handle_;
  HidListing listing_;
};

}  // namespace

std::vector<HidListing> ListHidDevices() {
  InitHidapi();
  std::vector<HidListing> out;
  hid_device_info* list = hid_enumerate(kUsbVendorId, kUsbProductId);
  for (hid_device_info* d = list; d != nullptr; d = d->next) {
    // The hidraw backend reads the usage page from the report descriptor.
    if (d->usage_page != wire::kHidUsagePage) continue;
    out.push_back(HidListing{.path = d->path,
                             .serial = Narrow(d->serial_number),
                             .product = Narrow(d->product_string),
                             .release = d->release_number});
  }
  hid_free_enumeration(list);
  return out;
}

std::unique_ptr<Transport> OpenHid(const std::string& serial) {
  const std::vector<HidListing> all = ListHidDevices();
  std::vector<HidListing> match;
  std::copy_if(all.begin(), all.end(), std::back_inserter(match),
               [&](const HidListing& l) { return serial.empty() || l.serial == serial; });
  if (match.empty()) {
    throw DeviceError(serial.empty() ? "no vibid board on USB HID"
                                     : "no vibid board with serial " + serial + " on USB HID");
  }
  if (match.size() > 1) {
    throw DeviceError(std::to_string(match.size()) +
                      " vibid boards on USB HID: choose one with --device hid:SERIAL");
  }
  hid_device* h = hid_open_path(match[0].path.c_str());
  if (h == nullptr) {
    throw DeviceError("cannot open " + match[0].path +
                      " (permissions? see the udev rule in README)");
  }
  return std::make_unique<HidTransport>(h, match[0]);
}

}  // namespace vibid::device
