#include "usbip_server.hpp"

#include <poll.h>

#include <algorithm>
#include <array>
#include <cstdio>

namespace vibid::emu {

UsbIpServer::UsbIpServer(const std::string& bind_address, std::uint16_t port, bool verbose)
    : listener_(bind_address, port), verbose_(verbose) {}

void UsbIpServer::SetDevice(ExportedDevice* device) {
  DropImporter();
  device_ = device;
}

void UsbIpServer::DropImporter() {
  if (importer_ == nullptr) return;
  Close(*importer_);
  Sweep();
}

void UsbIpServer::Close(Connection& c) {
  if (&c == importer_) {
    if (verbose_) std::fprintf(stderr, "vibid-emu: USB/IP client detached\n");
    importer_ = nullptr;
    if (device_ != nullptr) device_->Detach();
  }
  c.socket.Close();
}

void UsbIpServer::Sweep() {
  std::erase_if(connections_,
                [](const std::unique_ptr<Connection>& c) { return !c->socket.valid(); });
}

bool UsbIpServer::Poll(std::chrono::milliseconds timeout) {
  std::vector<pollfd> fds;
  fds.push_back({listener_.fd(), POLLIN, 0});
  for (const auto& c : connections_) fds.push_back({c->socket.fd(), POLLIN, 0});
  const int ready = ::poll(fds.data(), fds.size(), static_cast<int>(timeout.count()));
  if (ready <= 0) return false;

  bool handled = false;
  // Connections first (their indices match fds[1..]); new connections are appended after.
  const std::size_t existing = connections_.size();
  for (std::size_t i = 0; i < existing; ++i) {
    if ((fds[i + 1].revents & (POLLIN | POLLHUP | POLLERR)) == 0) continue;
    Connection& c = *connections_[i];
    if (!c.socket.valid()) continue;
    try {
      if (c.importing) {
        HandleUrb(c);
      } else {
        HandleOperation(c);
      }
    } catch (const std::exception& e) {
      std::fprintf(stderr, "vibid-emu: USB/IP client dropped: %s\n", e.what());
      Close(c);
    }
    handled = true;
  }
  if ((fds[0].revents & POLLIN) != 0) {
    usbip::Socket s = listener_.Accept(std::chrono::milliseconds(0));
    if (s.valid()) {
      auto c = std::make_unique<Connection>();
      c->socket = std::move(s);
      connections_.push_back(std::move(c));
    }
    handled = true;
  }
  Sweep();
  return handled;
}

void UsbIpServer::HandleOperation(Connection& c) {
  std::array<std::uint8_t, usbip::kOpHeaderBytes> head{};
  if (!c.socket.ReceiveExactOrEof(head)) {
    Close(c);
    return;
  }
  const usbip::OpHeader h = usbip::DecodeOpHeader(head);
  if (h.code == usbip::OpCode::kReqDevlist) {
    std::vector<usbip::UsbDevice> list;
    if (device_ != nullptr) list.push_back(device_->Describe());
    c.socket.SendAll(usbip::EncodeRepDevlist(list));
    Close(c);
    return;
  }
  if (h.code != usbip::OpCode::kReqImport)
    throw usbip::ProtocolError("unexpected operation in a request");
  std::array<std::uint8_t, usbip::kBusIdBytes> busid_bytes{};
  c.socket.ReceiveExact(busid_bytes);
  const std::string busid = usbip::DecodeBusId(busid_bytes);
  if (device_ == nullptr || busid != kBusId || importer_ != nullptr) {
    c.socket.SendAll(usbip::EncodeRepImport(nullptr));
    Close(c);
    return;
  }
  const usbip::UsbDevice record = device_->Describe();
  c.socket.SendAll(usbip::EncodeRepImport(&record));
  c.importing = true;
  importer_ = &c;
  if (verbose_) std::fprintf(stderr, "vibid-emu: USB/IP client imported %s\n", busid.c_str());
  device_->Attach(*this);
}

void UsbIpServer::HandleUrb(Connection& c) {
  usbip::UrbHeader h;
  if (!usbip::ReceiveUrbHeader(c.socket, h)) {
    Close(c);
    return;
  }
  switch (h.basic.command) {
    case usbip::UrbCommand::kCmdSubmit: {
      Urb urb;
      urb.seqnum = h.cmd_submit.basic.seqnum;
      urb.endpoint = static_cast<std::uint8_t>(h.cmd_submit.basic.ep & 0x0F);
      urb.direction = h.cmd_submit.basic.direction;
      urb.setup = h.cmd_submit.setup;
      urb.length = h.cmd_submit.transfer_buffer_length;
      urb.start_frame = h.cmd_submit.start_frame;
      urb.number_of_packets = h.cmd_submit.number_of_packets;
      const std::size_t payload = usbip::SubmitPayloadBytes(h.cmd_submit);
      if (payload > 65536)
        throw usbip::ProtocolError("URB of " + std::to_string(payload) + " bytes");
      urb.out_data.resize(payload);
      c.socket.ReceiveExact(urb.out_data);
      ++urbs_submitted_;
      if (device_ != nullptr) device_->Submit(std::move(urb));
      return;
    }
    case usbip::UrbCommand::kCmdUnlink: {
      const bool cancelled = device_ != nullptr && device_->Unlink(h.cmd_unlink.unlink_seqnum);
      if (cancelled) ++urbs_unlinked_;
      usbip::RetUnlink r;
      r.basic.seqnum = h.cmd_unlink.basic.seqnum;
      r.status = cancelled ? usbip::kStatusUnlinked : usbip::kStatusOk;
      std::array<std::uint8_t, usbip::kUrbHeaderBytes> bytes{};
      usbip::Encode(r, bytes);
      c.socket.SendAll(bytes);
      return;
    }
    default: throw usbip::ProtocolError("a client sent a reply-type URB message");
  }
}

void UsbIpServer::Complete(const Urb& urb, const UrbResult& result) {
  if (importer_ == nullptr) return;
  usbip::RetSubmit r;
  r.basic.seqnum = urb.seqnum;
  r.status = result.status;
  const bool in = urb.direction == usbip::Direction::kIn;
  r.actual_length = in ? static_cast<std::uint32_t>(result.in_data.size()) : result.actual_length;
  r.start_frame = urb.start_frame;
  r.number_of_packets = urb.number_of_packets;
  std::vector<std::uint8_t> bytes(usbip::kUrbHeaderBytes);
  usbip::Encode(
      r, std::span<std::uint8_t, usbip::kUrbHeaderBytes>(bytes.data(), usbip::kUrbHeaderBytes));
  if (in) bytes.insert(bytes.end(), result.in_data.begin(), result.in_data.end());
  try {
    importer_->socket.SendAll(bytes);
  } catch (const usbip::IoError& e) {
    // Completions arrive from inside the device's own processing: only shut the socket here;
    // the next Poll sees the hang-up and detaches the device outside of it.
    std::fprintf(stderr, "vibid-emu: USB/IP client dropped: %s\n", e.what());
    importer_->socket.Shutdown();
  }
}

}  // namespace vibid::emu
