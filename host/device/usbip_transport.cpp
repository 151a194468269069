#include "vibid/device/usbip_transport.hpp"

#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <map>
#include <mutex>
#include <thread>

#include "vibid/device/error.hpp"
#include "vibid/device/hid_transport.hpp"

namespace vibid::device {
namespace {

// USB/IP constants (usbip_protocol.rst). Every field is big-endian on the wire.
constexpr std::uint16_t kUsbipVersion = 0x0111;
constexpr std::uint16_t kOpReqDevlist = 0x8005;
constexpr std::uint16_t kOpRepDevlist = 0x0005;
constexpr std::uint16_t kOpReqImport = 0x8003;
constexpr std::uint16_t kOpRepImport = 0x0003;
constexpr std::uint32_t kCmdSubmit = 1;
constexpr std::uint32_t kRetSubmit = 3;
constexpr std::uint32_t kRetUnlink = 4;
constexpr std::uint32_t kDirOut = 0;
constexpr std::uint32_t kDirIn = 1;
constexpr std::size_t kBusidBytes = 32;
constexpr std::size_t kDeviceRecordBytes = 256 + 32 + 12 + 12;  // path, busid, bus/dev/speed, ids..
constexpr std::size_t kUrbHeaderBytes = 48;
/// Interrupt IN URBs kept queued, so the device always has somewhere to put its next report.
constexpr int kInUrbs = 4;

void PutBe16(std::vector<std::uint8_t>& b, std::uint16_t v) {
  b.push_back(static_cast<std::uint8_t>(v >> 8));
  b.push_back(static_cast<std::uint8_t>(v));
}
void PutBe32(std::vector<std::uint8_t>& b, std::uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) b.push_back(static_cast<std::uint8_t>(v >> s));
}
std::uint16_t Be16(const std::uint8_t* p) { return static_cast<std::uint16_t>((p[0] << 8) | p[1]); }
std::uint32_t Be32(const std::uint8_t* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) | p[3];
}

class Socket {
 public:
  Socket(const std::string& host, int port, std::chrono::milliseconds timeout) : where_(host + ":" + std::to_string(port)) {
    addrinfo hints{};
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_STREAM;
    addrinfo* res = nullptr;
    if (getaddrinfo(host.c_str(), std::to_string(port).c_str(), &hints, &res) != 0 || res == nullptr) {
      throw DeviceError("cannot resolve USB/IP server " + where_);
    }
    for (addrinfo* a = res; a != nullptr && fd_ < 0; a = a->ai_next) {
      fd_ = ::socket(a->ai_family, a->ai_socktype, a->ai_protocol);
      if (fd_ < 0) continue;
      if (::connect(fd_, a->ai_addr, a->ai_addrlen) != 0) {
        ::close(fd_);
        fd_ = -1;
      }
    }
    freeaddrinfo(res);
    if (fd_ < 0) throw DeviceError("no USB/IP server at " + where_ + " (is vibid-emu running?)");
    timeout_ = timeout;
  }
  ~Socket() { if (fd_ >= 0) ::close(fd_); }
  Socket(const Socket&) = delete;
  Socket& operator=(const Socket&) = delete;

  void WriteAll(std::span<const std::uint8_t> b) {
    std::size_t done = 0;
    while (done < b.size()) {
      const ssize_t n = ::send(fd_, b.data() + done, b.size() - done, MSG_NOSIGNAL);
      if (n <= 0) throw DeviceError("connection to " + where_ + " closed");
      done += static_cast<std::size_t>(n);
    }
  }
  /// Reads exactly b.size() bytes; `wait` false blocks without a timeout (the URB pump).
  void ReadAll(std::span<std::uint8_t> b, bool wait = true) {
    std::size_t done = 0;
    while (done < b.size()) {
      if (wait) {
        pollfd p{fd_, POLLIN, 0};
        if (::poll(&p, 1, static_cast<int>(timeout_.count())) <= 0) {
          throw DeviceError("USB/IP server " + where_ + " did not answer");
        }
      }
      const ssize_t n = ::recv(fd_, b.data() + done, b.size() - done, 0);
      if (n <= 0) throw DeviceError("connection to " + where_ + " closed");
      done += static_cast<std::size_t>(n);
    }
  }
  void Shutdown() { ::shutdown(fd_, SHUT_RDWR); }
  const std::string& where() const { return where_; }

 private:
  int fd_ = -1;
  std::string where_;
  std::chrono::milliseconds timeout_{1000};
};

std::vector<std::uint8_t> OpHeader(std::uint16_t code) {
  std::vector<std::uint8_t> b;
  PutBe16(b, kUsbipVersion);
  PutBe16(b, code);
  PutBe32(b, 0);
  return b;
}

void CheckOpReply(Socket& s, std::uint16_t expected) {
  std::array<std::uint8_t, 8> h{};
  s.ReadAll(h);
  if (Be16(&h[2]) != expected) throw DeviceError("USB/IP server " + s.where() + " answered with an unexpected reply");
  if (Be32(&h[4]) != 0) throw DeviceError("USB/IP server " + s.where() + " refused the request (status " + std::to_string(Be32(&h[4])) + ")");
}

UsbipExport ParseDeviceRecord(const std::uint8_t* d) {
  UsbipExport e;
  const char* busid = reinterpret_cast<const char*>(d + 256);
  e.busid.assign(busid, strnlen(busid, kBusidBytes));
  e.vendor_id = Be16(d + 300);
  e.product_id = Be16(d + 302);
  e.release = Be16(d + 304);
  e.interfaces = d[311];
  return e;
}

}  // namespace

std::vector<UsbipExport> ListUsbipExports(const std::string& host, int port, std::chrono::milliseconds timeout) {
  Socket s(host, port, timeout);
  s.WriteAll(OpHeader(kOpReqDevlist));
  CheckOpReply(s, kOpRepDevlist);
  std::array<std::uint8_t, 4> n{};
  s.ReadAll(n);
  std::vector<UsbipExport> out;
  for (std::uint32_t i = 0; i < Be32(n.data()); ++i) {
    std::array<std::uint8_t, kDeviceRecordBytes> d{};
    s.ReadAll(d);
    out.push_back(ParseDeviceRecord(d.data()));
    std::vector<std::uint8_t> ifaces(4u * out.back().interfaces);
    s.ReadAll(ifaces);
  }
  return out;
}

class UsbipDevice::Impl {
 public:
  enum class Kind { kInterruptIn, kInterruptOut, kControl };
  struct Pending {
    Kind kind = Kind::kControl;
    bool in = false;
    bool done = false;
    std::int32_t status = 0;
    std::vector<std::uint8_t> data;
  };

  Impl(const std::string& host, int port) : socket(host, port, std::chrono::milliseconds(2000)) {}

  void Start() { pump = std::thread([this] { Pump(); }); }

  ~Impl() {
    stopping = true;
    socket.Shutdown();
    if (pump.joinable()) pump.join();
  }

  std::uint32_t Submit(Kind kind, bool in, std::uint8_t endpoint, std::span<const std::uint8_t> out,
                       std::uint32_t in_length, const std::array<std::uint8_t, 8>& setup) {
    std::vector<std::uint8_t> b;
    std::uint32_t seq = 0;
    {
      std::lock_guard lock(mutex);
      if (!error.empty()) throw DeviceError(error);
      seq = ++seqnum;
      pending[seq] = Pending{.kind = kind, .in = in, .done = false, .status = 0, .data = {}};
    }
    PutBe32(b, kCmdSubmit);
    PutBe32(b, seq);
    PutBe32(b, devid);
    PutBe32(b, in ? kDirIn : kDirOut);
    PutBe32(b, endpoint & 0x0Fu);
    PutBe32(b, 0);  // transfer_flags
    PutBe32(b, in ? in_length : static_cast<std::uint32_t>(out.size()));
    PutBe32(b, 0);  // start_frame
    PutBe32(b, 0xFFFFFFFFu);  // number_of_packets: not isochronous
    PutBe32(b, kind == Kind::kControl ? 0 : 1);  // interval (bInterval 1)
    b.insert(b.end(), setup.begin(), setup.end());
    if (!in) b.insert(b.end(), out.begin(), out.end());
    std::lock_guard wlock(write_mutex);
    try {
      socket.WriteAll(b);
    } catch (const DeviceError& e) {
      Fail(e.what());
      throw;
    }
    return seq;
  }

  void Fail(const std::string& what) {
    std::lock_guard lock(mutex);
    if (error.empty()) error = what;
    changed.notify_all();
  }

  void Pump() {
    try {
      for (;;) {
        std::array<std::uint8_t, kUrbHeaderBytes> h{};
        socket.ReadAll(h, false);
        const std::uint32_t command = Be32(&h[0]);
        const std::uint32_t seq = Be32(&h[4]);
        if (command == kRetUnlink) continue;
        if (command != kRetSubmit) throw DeviceError("USB/IP server " + socket.where() + " sent an unknown reply");
        const auto status = static_cast<std::int32_t>(Be32(&h[20]));
        const std::uint32_t actual = Be32(&h[24]);
        bool in = false;
        Kind kind = Kind::kControl;
        {
          std::lock_guard lock(mutex);
          auto it = pending.find(seq);
          if (it == pending.end()) throw DeviceError("USB/IP server " + socket.where() + " completed an unknown URB");
          in = it->second.in;
          kind = it->second.kind;
        }
        std::vector<std::uint8_t> data(in ? actual : 0);
        if (actual > 0x10000) throw DeviceError("USB/IP server " + socket.where() + " sent an oversize URB");
        socket.ReadAll(data, false);
        std::unique_lock lock(mutex);
        if (kind == Kind::kInterruptIn) {
          pending.erase(seq);
          if (status == 0) reports.push_back(std::move(data));
          lock.unlock();
          changed.notify_all();
          if (!stopping && status == 0) Submit(Kind::kInterruptIn, true, in_endpoint, {}, wire::kReportBytes, {});
          continue;
        }
        if (kind == Kind::kInterruptOut) {
          pending.erase(seq);
          if (status != 0 && error.empty()) error = "the device refused a HID report (URB status " + std::to_string(status) + ")";
          changed.notify_all();
          continue;
        }
        Pending& p = pending[seq];
        p.done = true;
        p.status = status;
        p.data = std::move(data);
        changed.notify_all();
      }
    } catch (const std::exception& e) {
      Fail(stopping ? "closed" : e.what());
    }
  }

  Socket socket;
  std::uint32_t devid = 0;
  std::string busid;
  std::uint8_t in_endpoint = 0x81;
  std::uint8_t out_endpoint = 0x01;
  std::vector<std::uint8_t> device_descriptor;
  std::vector<std::uint8_t> configuration;

  std::mutex write_mutex;
  std::mutex mutex;
  std::condition_variable changed;
  std::map<std::uint32_t, Pending> pending;
  std::deque<std::vector<std::uint8_t>> reports;
  std::string error;
  std::uint32_t seqnum = 0;
  std::atomic<bool> stopping{false};
  std::thread pump;
};

UsbipDevice::UsbipDevice(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
UsbipDevice::~UsbipDevice() = default;

std::unique_ptr<UsbipDevice> UsbipDevice::Open(const std::string& host, int port, const std::string& busid_in,
                                               std::uint16_t vendor_id, std::uint16_t product_id) {
  std::string busid = busid_in;
  if (busid.empty()) {
    std::vector<std::string> ours;
    for (const UsbipExport& e : ListUsbipExports(host, port)) {
      if (e.vendor_id == vendor_id && e.product_id == product_id) ours.push_back(e.busid);
    }
    const std::string where = host + ":" + std::to_string(port);
    if (ours.empty()) throw DeviceError("the USB/IP server at " + where + " exports no vibid device");
    if (ours.size() > 1) throw DeviceError("the USB/IP server at " + where + " exports several vibid devices");
    busid = ours[0];
  }
  auto impl = std::make_unique<Impl>(host, port);
  Socket& s = impl->socket;
  std::vector<std::uint8_t> req = OpHeader(kOpReqImport);
  std::array<std::uint8_t, kBusidBytes> id{};
  std::copy_n(busid.begin(), std::min(busid.size(), kBusidBytes - 1), id.begin());
  req.insert(req.end(), id.begin(), id.end());
  s.WriteAll(req);
  CheckOpReply(s, kOpRepImport);
  std::array<std::uint8_t, kDeviceRecordBytes> d{};
  s.ReadAll(d);
  impl->devid = (Be32(&d[288]) << 16) | (Be32(&d[292]) & 0xFFFFu);
  impl->busid = busid;
  impl->Start();
  std::unique_ptr<UsbipDevice> dev(new UsbipDevice(std::move(impl)));
  Impl& m = *dev->impl_;

  // Enumeration as a host controller driver does it.
  m.device_descriptor = GetDescriptor(*dev, kDescriptorDevice, 0, 18);
  if (m.device_descriptor.size() != 18) throw DeviceError("malformed device descriptor from " + dev->Describe());
  const std::vector<std::uint8_t> head = GetDescriptor(*dev, kDescriptorConfiguration, 0, 9);
  if (head.size() != 9) throw DeviceError("malformed configuration descriptor from " + dev->Describe());
  const auto total = static_cast<std::uint16_t>(head[2] | (head[3] << 8));
  m.configuration = GetDescriptor(*dev, kDescriptorConfiguration, 0, total);
  // The HID interface's interrupt endpoints (class 3).
  bool hid = false;
  bool has_hid_in = false;
  for (std::size_t i = 0; i + 1 < m.configuration.size() && m.configuration[i] >= 2; i += m.configuration[i]) {
    const std::uint8_t* p = &m.configuration[i];
    if (p[1] == 4 && i + 5 < m.configuration.size()) hid = p[5] == 3;
    if (p[1] == 5 && hid && i + 3 < m.configuration.size() && (p[3] & 3) == 3) {
      if ((p[2] & 0x80) != 0) {
        m.in_endpoint = p[2];
        has_hid_in = true;
      } else {
        m.out_endpoint = p[2];
      }
    }
  }
  Setup set;
  set.request = kSetConfiguration;
  set.value = head[5];  // bConfigurationValue
  static_cast<void>(dev->Control(set, {}, std::chrono::milliseconds(1000)));
  for (int i = 0; has_hid_in && i < kInUrbs; ++i) {
    static_cast<void>(m.Submit(Impl::Kind::kInterruptIn, true, m.in_endpoint, {}, wire::kReportBytes, {}));
  }
  return dev;
}

void UsbipDevice::Send(const wire::Report& report) {
  static_cast<void>(impl_->Submit(Impl::Kind::kInterruptOut, false, impl_->out_endpoint, report, 0, {}));
}

std::size_t UsbipDevice::Receive(std::span<std::uint8_t, wire::kReportBytes> out, std::chrono::milliseconds timeout) {
  std::unique_lock lock(impl_->mutex);
  impl_->changed.wait_for(lock, timeout, [&] { return !impl_->reports.empty() || !impl_->error.empty(); });
  if (!impl_->reports.empty()) {
    std::vector<std::uint8_t> r = std::move(impl_->reports.front());
    impl_->reports.pop_front();
    const std::size_t n = std::min(r.size(), out.size());
    std::copy_n(r.begin(), n, out.begin());
    return r.size() > out.size() ? 0 : n;
  }
  if (!impl_->error.empty()) throw DeviceError(impl_->error);
  return 0;
}

std::string UsbipDevice::Describe() const {
  return "usbip://" + impl_->socket.where() + " bus " + impl_->busid;
}

std::vector<std::uint8_t> UsbipDevice::Control(const Setup& setup, std::span<const std::uint8_t> out,
                                               std::chrono::milliseconds timeout) {
  const std::uint32_t seq = impl_->Submit(Impl::Kind::kControl, setup.In(), 0, out, setup.length, setup.Bytes());
  std::unique_lock lock(impl_->mutex);
  const bool done = impl_->changed.wait_for(lock, timeout, [&] {
    return impl_->pending[seq].done || !impl_->error.empty();
  });
  Impl::Pending p = impl_->pending[seq];
  impl_->pending.erase(seq);
  const std::string what = "control request " + std::to_string(setup.request) + " (type 0x" +
                           [&] { char b[3]; std::snprintf(b, 3, "%02x", setup.request_type); return std::string(b); }() + ")";
  if (!p.done) {
    if (!impl_->error.empty()) throw DeviceError(impl_->error);
    static_cast<void>(done);
    throw DeviceError(what + " timed out on " + Describe());
  }
  if (p.status != 0) throw DeviceError(what + " stalled on " + Describe());
  return p.data;
}

const std::vector<std::uint8_t>& UsbipDevice::device_descriptor() const { return impl_->device_descriptor; }
const std::vector<std::uint8_t>& UsbipDevice::configuration_descriptor() const { return impl_->configuration; }

}  // namespace vibid::device
