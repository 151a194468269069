#include "vibid/device/usbip_transport.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>

#include "vibid/device/error.hpp"
#include "vibid/usbip/protocol.hpp"
#include "vibid/usbip/socket.hpp"

namespace vibid::device {
namespace {

/// Interrupt IN URBs kept queued, so the device always has somewhere to put its next report, as
/// the kernel's HID driver polls every frame. The emulator's next frame waits while a report is
/// ready and none is queued; more of them means fewer such waits per TCP round trip.
constexpr int kInUrbs = 16;
constexpr std::chrono::milliseconds kConnectTimeout{2000};

std::string Where(const std::string& host, int port) { return host + ":" + std::to_string(port); }

usbip::Socket Connect(const std::string& host, int port, std::chrono::milliseconds timeout) {
  try {
    return usbip::ConnectTcp(host, static_cast<std::uint16_t>(port), timeout);
  } catch (const usbip::IoError&) {
    throw DeviceError("no USB/IP server at " + Where(host, port) + " (is vibid-emu running?)");
  }
}

UsbipExport ToExport(const usbip::UsbDevice& d) {
  return UsbipExport{.busid = d.busid,
                     .vendor_id = d.id_vendor,
                     .product_id = d.id_product,
                     .release = d.bcd_device,
                     .interfaces = d.num_interfaces,
                     .interface_classes = d.interfaces};
}

/// The inodes of the sockets in /proc/net/`table` connected to 127.0.0.1 (or ::1) port `port`:
/// the clients of a local USB/IP server.
std::vector<std::string> LocalClientSockets(const char* table, int port) {
  std::vector<std::string> inodes;
  std::ifstream in(std::string("/proc/net/") + table);
  std::string line;
  std::getline(in, line);  // the column names
  char want[8];
  std::snprintf(want, sizeof want, ":%04X", static_cast<unsigned>(port));
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    std::string sl, local, remote, state, queues, timer, retransmits, uid, timeout, inode;
    if (!(fields >> sl >> local >> remote >> state >> queues >> timer >> retransmits >> uid >>
          timeout >> inode))
      continue;
    const bool loopback = remote.rfind("0100007F:", 0) == 0 ||
                          remote.rfind("00000000000000000000000001000000:", 0) == 0;
    // 01: established.
    if (state == "01" && loopback && remote.size() >= 5 &&
        remote.compare(remote.size() - 5, 5, want) == 0)
      inodes.push_back(inode);
  }
  return inodes;
}

/// What holds the local USB/IP server at `port`: "vibid bench --out lab (pid 1234)", from the
/// process that owns a socket connected to it (Linux's /proc; another user's processes are not
/// readable, and a server on another machine cannot be asked): "" when it cannot tell.
std::string LocalHolder(const std::string& host, int port) {
  if (host != "127.0.0.1" && host != "localhost" && host != "::1") return {};
  std::vector<std::string> inodes = LocalClientSockets("tcp", port);
  for (const std::string& i : LocalClientSockets("tcp6", port)) inodes.push_back(i);
  if (inodes.empty()) return {};
  std::error_code ec;
  const std::string self = std::to_string(::getpid());
  for (const auto& proc : std::filesystem::directory_iterator("/proc", ec)) {
    const std::string pid = proc.path().filename().string();
    if (pid.empty() || !std::all_of(pid.begin(), pid.end(), ::isdigit) || pid == self) continue;
    std::error_code fd_ec;
    for (const auto& fd : std::filesystem::directory_iterator(proc.path() / "fd", fd_ec)) {
      std::error_code link_ec;
      const std::string target = std::filesystem::read_symlink(fd.path(), link_ec).string();
      if (link_ec || target.rfind("socket:[", 0) != 0) continue;
      const std::string inode = target.substr(8, target.size() - 9);
      if (std::find(inodes.begin(), inodes.end(), inode) == inodes.end()) continue;
      // The command line, its words joined by spaces, the program without its folder.
      std::ifstream cmdline(proc.path() / "cmdline", std::ios::binary);
      std::string words, word;
      while (std::getline(cmdline, word, '\0')) {
        if (words.empty()) word = std::filesystem::path(word).filename().string();
        words += (words.empty() ? "" : " ") + word;
      }
      if (words.size() > 160) words = words.substr(0, 157) + "...";
      return (words.empty() ? "a process" : words) + " (pid " + pid + ")";
    }
  }
  return {};
}

}  // namespace

std::string UsbipBusyMessage(const std::string& host, int port) {
  const std::string holder = LocalHolder(host, port);
  return "the board at usbip://" + Where(host, port) + " is in use by " +
         (holder.empty() ? "another program (a vibid bench, a vibid command or a Python Board "
                           "holding it; its USB/IP server serves one client at a time)"
                         : holder) +
         ": close it, or wait until it ends, and try again";
}

std::vector<UsbipExport> ListUsbipExports(const std::string& host, int port,
                                          std::chrono::milliseconds timeout) {
  usbip::Socket s = Connect(host, port, timeout);
  std::vector<UsbipExport> out;
  try {
    for (const usbip::UsbDevice& d : usbip::RequestDeviceList(s)) out.push_back(ToExport(d));
  } catch (const std::runtime_error& e) {
    throw DeviceError("USB/IP server " + Where(host, port) + ": " + e.what());
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

  Impl(const std::string& host, int port)
      : socket(Connect(host, port, kConnectTimeout)), where(Where(host, port)) {}

  void Start() {
    pump = std::thread([this] { Pump(); });
  }

  ~Impl() {
    stopping = true;
    socket.Shutdown();
    if (pump.joinable()) pump.join();
  }

  std::uint32_t Submit(Kind kind, bool in, std::uint8_t endpoint, std::span<const std::uint8_t> out,
                       std::uint32_t in_length, const std::array<std::uint8_t, 8>& setup) {
    usbip::CmdSubmit cmd;
    {
      std::lock_guard lock(mutex);
      if (!error.empty()) throw DeviceError(error);
      cmd.basic.seqnum = ++seqnum;
      pending[cmd.basic.seqnum] =
          Pending{.kind = kind, .in = in, .done = false, .status = 0, .data = {}};
    }
    cmd.basic.command = usbip::UrbCommand::kCmdSubmit;
    cmd.basic.devid = devid;
    cmd.basic.direction = in ? usbip::Direction::kIn : usbip::Direction::kOut;
    cmd.basic.ep = endpoint & 0x0Fu;
    cmd.transfer_buffer_length = in ? in_length : static_cast<std::uint32_t>(out.size());
    cmd.interval = kind == Kind::kControl ? 0 : 1;  // bInterval 1 on the HID endpoints
    cmd.setup = setup;
    std::vector<std::uint8_t> b(usbip::kUrbHeaderBytes);
    usbip::Encode(cmd, std::span<std::uint8_t, usbip::kUrbHeaderBytes>(b.data(), b.size()));
    if (!in) b.insert(b.end(), out.begin(), out.end());
    std::lock_guard wlock(write_mutex);
    try {
      socket.SendAll(b);
    } catch (const usbip::IoError& e) {
      Fail(std::string("connection to ") + where + " closed");
      throw DeviceError(std::string("connection to ") + where + " closed");
    }
    return cmd.basic.seqnum;
  }

  void Fail(const std::string& what) {
    std::lock_guard lock(mutex);
    if (error.empty()) error = what;
    changed.notify_all();
  }

  void Pump() {
    try {
      for (;;) {
        usbip::UrbHeader h;
        if (!usbip::ReceiveUrbHeader(socket, h))
          throw DeviceError("connection to " + where + " closed");
        if (h.basic.command == usbip::UrbCommand::kRetUnlink) continue;
        if (h.basic.command != usbip::UrbCommand::kRetSubmit) {
          throw DeviceError("USB/IP server " + where + " sent a request instead of a reply");
        }
        const std::uint32_t seq = h.basic.seqnum;
        const std::int32_t status = h.ret_submit.status;
        const std::uint32_t actual = h.ret_submit.actual_length;
        bool in = false;
        Kind kind = Kind::kControl;
        {
          std::lock_guard lock(mutex);
          auto it = pending.find(seq);
          if (it == pending.end())
            throw DeviceError("USB/IP server " + where + " completed an unknown URB");
          in = it->second.in;
          kind = it->second.kind;
        }
        if (actual > 0x10000) throw DeviceError("USB/IP server " + where + " sent an oversize URB");
        std::vector<std::uint8_t> data(in ? actual : 0);
        socket.ReceiveExact(data);
        std::unique_lock lock(mutex);
        if (kind == Kind::kInterruptIn) {
          pending.erase(seq);
          if (status == usbip::kStatusOk) reports.push_back(std::move(data));
          lock.unlock();
          changed.notify_all();
          if (!stopping && status == usbip::kStatusOk) {
            Submit(Kind::kInterruptIn, true, in_endpoint, {}, wire::kReportBytes, {});
          }
          continue;
        }
        if (kind == Kind::kInterruptOut) {
          pending.erase(seq);
          if (status != usbip::kStatusOk && error.empty()) {
            error = "the device refused a HID report (URB status " + std::to_string(status) + ")";
          }
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

  usbip::Socket socket;
  std::string where;
  std::uint32_t devid = 0;
  std::string busid;
  std::uint8_t in_endpoint = 0x81;
  std::uint8_t out_endpoint = 0x01;
  std::vector<std::uint8_t> device_descriptor;
  std::vector<std::uint8_t> configuration;
  std::string serial;  ///< iSerialNumber, read at enumeration.

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

std::unique_ptr<UsbipDevice> UsbipDevice::Open(const std::string& host, int port,
                                               const std::string& busid_in, std::uint16_t vendor_id,
                                               std::uint16_t product_id) {
  std::string busid = busid_in;
  if (busid.empty()) {
    std::vector<std::string> ours;
    for (const UsbipExport& e : ListUsbipExports(host, port)) {
      if (e.vendor_id == vendor_id && e.product_id == product_id) ours.push_back(e.busid);
    }
    const std::string where = host + ":" + std::to_string(port);
    if (ours.empty())
      throw DeviceError("the USB/IP server at " + where + " exports no vibid device");
    if (ours.size() > 1)
      throw DeviceError("the USB/IP server at " + where + " exports several vibid devices");
    busid = ours[0];
  }
  auto impl = std::make_unique<Impl>(host, port);
  try {
    const usbip::UsbDevice d = usbip::RequestImport(impl->socket, busid);
    impl->devid = d.devid();
  } catch (const std::runtime_error& e) {
    // A server that still lists the device but will not export it has given it to another
    // client: the board is in use, which the user can do something about.
    bool listed = false;
    try {
      for (const UsbipExport& x : ListUsbipExports(host, port)) listed = listed || x.busid == busid;
    } catch (const DeviceError&) {
    }
    if (listed) throw DeviceError(UsbipBusyMessage(host, port));
    throw DeviceError("USB/IP server " + impl->where + " refused to export " + busid + ": " +
                      e.what());
  }
  impl->busid = busid;
  impl->Start();
  std::unique_ptr<UsbipDevice> dev(new UsbipDevice(std::move(impl)));
  Impl& m = *dev->impl_;

  // Enumeration as a host controller driver does it.
  m.device_descriptor = GetDescriptor(*dev, kDescriptorDevice, 0, 18);
  if (m.device_descriptor.size() != 18)
    throw DeviceError("malformed device descriptor from " + dev->Describe());
  const std::vector<std::uint8_t> head = GetDescriptor(*dev, kDescriptorConfiguration, 0, 9);
  if (head.size() != 9)
    throw DeviceError("malformed configuration descriptor from " + dev->Describe());
  const auto total = static_cast<std::uint16_t>(head[2] | (head[3] << 8));
  m.configuration = GetDescriptor(*dev, kDescriptorConfiguration, 0, total);
  // The serial number names the board in its recordings; a device without one has index 0.
  if (m.device_descriptor[16] != 0) {
    try {
      m.serial = GetStringDescriptor(*dev, m.device_descriptor[16]);
    } catch (const DeviceError&) {
      m.serial.clear();
    }
  }
  // The HID interface's interrupt endpoints (class 3).
  bool hid = false;
  bool has_hid_in = false;
  for (std::size_t i = 0; i + 1 < m.configuration.size() && m.configuration[i] >= 2;
       i += m.configuration[i]) {
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
    static_cast<void>(
        m.Submit(Impl::Kind::kInterruptIn, true, m.in_endpoint, {}, wire::kReportBytes, {}));
  }
  return dev;
}

void UsbipDevice::Send(const wire::Report& report) {
  static_cast<void>(
      impl_->Submit(Impl::Kind::kInterruptOut, false, impl_->out_endpoint, report, 0, {}));
}

std::size_t UsbipDevice::Receive(std::span<std::uint8_t, wire::kReportBytes> out,
                                 std::chrono::milliseconds timeout) {
  std::unique_lock lock(impl_->mutex);
  impl_->changed.wait_for(lock, timeout,
                          [&] { return !impl_->reports.empty() || !impl_->error.empty(); });
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

std::string UsbipDevice::SerialNumber() const { return impl_->serial; }

std::string UsbipDevice::Describe() const {
  return "usbip://" + impl_->where + " bus " + impl_->busid;
}

std::vector<std::uint8_t> UsbipDevice::Control(const Setup& setup,
                                               std::span<const std::uint8_t> out,
                                               std::chrono::milliseconds timeout) {
  const std::uint32_t seq =
      impl_->Submit(Impl::Kind::kControl, setup.In(), 0, out, setup.length, setup.Bytes());
  std::unique_lock lock(impl_->mutex);
  const bool done = impl_->changed.wait_for(
      lock, timeout, [&] { return impl_->pending[seq].done || !impl_->error.empty(); });
  Impl::Pending p = impl_->pending[seq];
  impl_->pending.erase(seq);
  const std::string what = "control request " + std::to_string(setup.request) + " (type 0x" + [&] {
    char b[3];
    std::snprintf(b, 3, "%02x", setup.request_type);
    return std::string(b);
  }() + ")";
  if (!p.done) {
    if (!impl_->error.empty()) throw DeviceError(impl_->error);
    static_cast<void>(done);
    throw DeviceError(what + " timed out on " + Describe());
  }
  if (p.status != 0) throw DeviceError(what + " stalled on " + Describe());
  return p.data;
}

const std::vector<std::uint8_t>& UsbipDevice::device_descriptor() const {
  return impl_->device_descriptor;
}
const std::vector<std::uint8_t>& UsbipDevice::configuration_descriptor() const {
  return impl_->configuration;
}

}  // namespace vibid::device
