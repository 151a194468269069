// Test harness: a fake controller driver that records what the stack asks of the hardware, and a
// minimal host side that runs control transfers against it packet by packet, following the
// host's rules (a data stage ends at wLength bytes or a short packet; then the status stage).
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "vibid/fw/usb/dcd.hpp"
#include "vibid/fw/usb/device.hpp"
#include "vibid/fw/usb/dfu_runtime.hpp"
#include "vibid/fw/usb/hid_class.hpp"

namespace vibid::fw::usb::testing {

class FakeDcd final : public Dcd {
 public:
  struct Pending {
    bool active = false;
    std::span<std::uint8_t> buffer{};
  };

  Status Init(DcdEvents& events) override {
    events_ = &events;
    return init_status;
  }
  void Connect() override { connected = true; }
  void Disconnect() override { connected = false; }
  void SetAddress(std::uint8_t a) override { address = a; }
  Status EndpointOpen(std::uint8_t ep, EndpointType type, std::uint16_t max_packet) override {
    opened[Index(ep)] = true;
    open_type[Index(ep)] = type;
    open_size[Index(ep)] = max_packet;
    return Status::kOk;
  }
  void EndpointCloseAll() override {
    for (std::size_t i = 0; i < 32; ++i) {
      if (i % 16 != 0) {
        opened[i] = false;
        pending[i] = {};
      }
    }
  }
  void EndpointStall(std::uint8_t ep) override {
    stalled[Index(ep)] = true;
    if (EpNumber(ep) != 0) pending[Index(ep)] = {};
  }
  void EndpointClearStall(std::uint8_t ep) override {
    stalled[Index(ep)] = false;
    ++clear_stall_calls;
  }
  Status Transfer(std::uint8_t ep, std::span<std::uint8_t> buffer) override {
    if (pending[Index(ep)].active) return Status::kUnavailable;
    pending[Index(ep)] = Pending{true, buffer};
    return Status::kOk;
  }

  static std::size_t Index(std::uint8_t ep) { return EpNumber(ep) + (IsIn(ep) ? 16U : 0U); }
  Pending& PendingOn(std::uint8_t ep) { return pending[Index(ep)]; }
  bool Stalled(std::uint8_t ep) const { return stalled[Index(ep)]; }
  /// Hardware clears endpoint 0's stall when the next SETUP arrives.
  void OnSetupHardware() {
    stalled[0] = false;
    stalled[16] = false;
    pending[0] = {};
    pending[16] = {};
  }

  Status init_status = Status::kOk;
  bool connected = false;
  std::uint8_t address = 0;
  std::uint32_t clear_stall_calls = 0;
  std::array<bool, 32> opened{};
  std::array<EndpointType, 32> open_type{};
  std::array<std::uint16_t, 32> open_size{};
  std::array<bool, 32> stalled{};
  std::array<Pending, 32> pending{};

 private:
  DcdEvents* events_ = nullptr;
};

/// Result of one control transfer as the host sees it.
struct ControlResult {
  bool stalled = false;
  bool protocol_error = false;  ///< The device did not arm the stage the host expected.
  std::size_t packets = 0;      ///< Data-stage packets, a terminating ZLP included.
  std::size_t length = 0;
  std::array<std::uint8_t, 512> data{};
  std::span<const std::uint8_t> Bytes() const { return std::span(data).first(length); }
};

class Host {
 public:
  Host(UsbDevice& device, FakeDcd& dcd) : device_(device), dcd_(dcd) {}

  void BusReset() {
    device_.OnBusReset();
    device_.Task();
  }

  /// Runs SETUP (+ IN data) + status. `out_data` is sent in the OUT data stage when the request
  /// is host-to-device with wLength > 0.
  ControlResult Control(std::array<std::uint8_t, 8> setup,
                        std::span<const std::uint8_t> out_data = {}) {
    ControlResult r;
    dcd_.OnSetupHardware();
    device_.OnSetupReceived(setup);
    device_.Task();
    const auto packet = SetupPacket::Decode(setup);
    if (packet.DeviceToHost() && packet.w_length > 0) {
      while (true) {
        if (StalledNow()) return Stall(r);
        auto& in = dcd_.PendingOn(0x80);
        if (!in.active) return Error(r);
        const std::size_t n = in.buffer.size();
        if (n > kEp0Size || r.length + n > r.data.size()) return Error(r);
        std::copy_n(in.buffer.begin(), n, r.data.begin() + static_cast<std::ptrdiff_t>(r.length));
        r.length += n;
        ++r.packets;
        in = {};
        device_.OnTransferComplete(0x80, static_cast<std::uint16_t>(n));
        device_.Task();
        if (n < kEp0Size || r.length >= packet.w_length) break;
      }
      // Status stage: the host sends a zero-length OUT.
      if (StalledNow()) return Stall(r);
      auto& out = dcd_.PendingOn(0x00);
      if (!out.active) return Error(r);
      out = {};
      device_.OnTransferComplete(0x00, 0);
      device_.Task();
      return r;
    }
    std::size_t sent = 0;
    while (sent < packet.w_length) {
      if (StalledNow()) return Stall(r);
      auto& out = dcd_.PendingOn(0x00);
      if (!out.active) return Error(r);
      const std::size_t n =
          std::min<std::size_t>({kEp0Size, packet.w_length - sent, out_data.size() - sent});
      if (n > out.buffer.size()) return Error(r);
      std::copy_n(out_data.begin() + static_cast<std::ptrdiff_t>(sent), n, out.buffer.begin());
      sent += n;
      out = {};
      device_.OnTransferComplete(0x00, static_cast<std::uint16_t>(n));
      device_.Task();
      if (n < kEp0Size) break;
    }
    // Status stage: the device sends a zero-length IN.
    if (StalledNow()) return Stall(r);
    auto& in = dcd_.PendingOn(0x80);
    if (!in.active || !in.buffer.empty()) return Error(r);
    in = {};
    device_.OnTransferComplete(0x80, 0);
    device_.Task();
    return r;
  }

  /// Bus reset, SET_ADDRESS, SET_CONFIGURATION 1: the shortest path to a configured device.
  void Enumerate(std::uint8_t address) {
    BusReset();
    (void)Control({0x00, 0x05, address, 0x00, 0x00, 0x00, 0x00, 0x00});
    (void)Control({0x00, 0x09, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00});
  }

 private:
  bool StalledNow() const { return dcd_.Stalled(0x80) || dcd_.Stalled(0x00); }
  static ControlResult Stall(ControlResult r) {
    r.stalled = true;
    return r;
  }
  static ControlResult Error(ControlResult r) {
    r.protocol_error = true;
    return r;
  }

  UsbDevice& device_;
  FakeDcd& dcd_;
};

class RecordingDetach final : public DfuDetachHandler {
 public:
  void OnDetach(std::uint16_t timeout_ms) override {
    ++calls;
    last_timeout_ms = timeout_ms;
  }
  int calls = 0;
  std::uint16_t last_timeout_ms = 0;
};

/// The board's USB function as the ports assemble it: HID + DFU run-time over one device.
struct Rig {
  /// A 96-bit STM32 unique id printed as 24 hex digits, the way the ports form the serial.
  static constexpr const char* kSerial = "0123456789ABCDEF01234567";

  /// Starts the device with `serial`, on a controller whose Init answers `init_status`.
  explicit Rig(const char* serial = kSerial, Status init_status = Status::kOk)
      : strings(MakeDaqStrings(serial)) {
    dcd.init_status = init_status;
    start_status = device.Start();
  }

  FakeDcd dcd;
  HidClass hid;
  RecordingDetach detach;
  DfuRuntime dfu{detach};
  std::array<ClassDriver*, 2> drivers{&hid, &dfu};
  DaqStrings strings;
  UsbDevice device{dcd, drivers, DaqDescriptors(strings)};
  Host host{device, dcd};
  Status start_status = Status::kOk;  ///< What device.Start() answered.
};

}  // namespace vibid::fw::usb::testing
