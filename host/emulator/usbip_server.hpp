// The USB/IP server side (what `usbipd` does for a real device): lists and exports one device,
// then carries its URB traffic. Single-threaded: Poll() waits for socket activity with a timeout
// and handles whole messages; completions are sent as they happen.
//
// Connections in the operation phase get OP_REP_DEVLIST (then are closed, as usbipd does) or
// OP_REP_IMPORT. One client at a time holds the device; a second import is refused (status 1)
// until the first disconnects. When the device re-enumerates (reset, DFU entry or leave), the
// server drops the importing connection: the client sees the device go away and imports again.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "exported_device.hpp"
#include "vibid/usbip/socket.hpp"

namespace vibid::emu {

class UsbIpServer final : public UrbSink {
 public:
  static constexpr const char* kBusId = "1-1";

  /// @throws usbip::IoError when the address cannot be bound.
  /// `verbose`: one line on stderr per import and per disconnect.
  UsbIpServer(const std::string& bind_address, std::uint16_t port, bool verbose = false);

  std::uint16_t port() const { return listener_.port(); }

  /// The device to export (null: the device list is empty). Drops any importing connection.
  void SetDevice(ExportedDevice* device);

  /// Closes the importing connection (the device disappears from the client's bus).
  void DropImporter();

  /// Handles socket activity, waiting at most `timeout` for some.
  /// @returns true if at least one message was handled.
  bool Poll(std::chrono::milliseconds timeout);

  bool Imported() const { return importer_ != nullptr; }

  /// Counters for the log line and the tests.
  std::uint64_t urbs_submitted() const { return urbs_submitted_; }
  std::uint64_t urbs_unlinked() const { return urbs_unlinked_; }

  // UrbSink
  void Complete(const Urb& urb, const UrbResult& result) override;

 private:
  struct Connection {
    usbip::Socket socket;
    bool importing = false;  // URB phase
  };

  void HandleOperation(Connection& c);
  void HandleUrb(Connection& c);
  void Close(Connection& c);
  void Sweep();

  usbip::Listener listener_;
  bool verbose_;
  ExportedDevice* device_ = nullptr;
  std::vector<std::unique_ptr<Connection>> connections_;
  Connection* importer_ = nullptr;
  std::uint64_t urbs_submitted_ = 0;
  std::uint64_t urbs_unlinked_ = 0;
};

}  // namespace vibid::emu
