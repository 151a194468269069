#include "dfuse_bootloader.hpp"

#include <algorithm>

namespace vibid::emu {
namespace {

using dfu::DfuSeCommand;
using dfu::State;

constexpr std::uint8_t Byte(DfuSeCommand c) { return static_cast<std::uint8_t>(c); }

// Poll times the bootloader asks for (bwPollTimeout). Shorter than the silicon's (a 128 KiB
// sector erase takes about a second) because the emulated flash is a file, not because the
// protocol allows skipping the wait: the host must honour whatever is reported.
constexpr std::uint32_t kWritePollMs = 1;
constexpr std::uint32_t kSectorErasePollMs = 5;
constexpr std::uint32_t kMassErasePollMs = 20;

// DFU 1.1 table 4.2 functional descriptor: bmAttributes = canDnload | canUpload | willDetach
// (not manifestation tolerant: the device leaves after manifestation), wDetachTimeOut 255 ms,
// wTransferSize 2048, bcdDFUVersion 1.1a (0x011A: ST's DfuSe extension).
constexpr std::array<std::uint8_t, 18> kDeviceDescriptor = {
    18, 1, 0x00, 0x02, 0, 0, 0, 64, 0x83, 0x04, 0x11, 0xDF, 0x00, 0x22, 1, 2, 3, 1};
constexpr std::array<std::uint8_t, 27> kConfigurationDescriptor = {
    9,    2,    27,   0,   1,
    1,    0,    0xC0, 50,  // one interface, self powered, 100 mA
    9,    4,    0,    0,   0,
    0xFE, 0x01, 0x02, 4,  // application-specific class, DFU subclass, DFU mode
    9,    0x21, 0x0B, 255, 0,
    0x00, 0x08, 0x1A, 0x01};
static_assert(kConfigurationDescriptor[2] == kConfigurationDescriptor.size());

std::uint32_t Le32(const std::vector<std::uint8_t>& d, std::size_t at) {
  return std::uint32_t{d[at]} | (std::uint32_t{d[at + 1]} << 8) | (std::uint32_t{d[at + 2]} << 16) |
         (std::uint32_t{d[at + 3]} << 24);
}

UrbResult Data(std::vector<std::uint8_t> bytes, std::uint16_t length) {
  UrbResult r;
  if (bytes.size() > length) bytes.resize(length);
  r.actual_length = static_cast<std::uint32_t>(bytes.size());
  r.in_data = std::move(bytes);
  return r;
}

UrbResult Stall() {
  UrbResult r;
  r.status = usbip::kStatusStall;
  return r;
}

}  // namespace

DfuSeBootloader::DfuSeBootloader(FlashImage& flash, usbip::UsbDevice record, std::string serial)
    : flash_(flash), record_(std::move(record)), serial_(std::move(serial)) {}

usbip::UsbDevice DfuSeBootloader::Describe() const {
  usbip::UsbDevice d = record_;
  d.id_vendor = dfu::kStBootloaderVendorId;
  d.id_product = dfu::kStBootloaderProductId;
  d.bcd_device = 0x2200;
  d.device_class = d.device_subclass = d.device_protocol = 0;
  d.configuration_value = configuration_;
  d.num_configurations = 1;
  d.num_interfaces = 1;
  d.interfaces = {usbip::UsbInterface{0xFE, 0x01, 0x02}};
  return d;
}

void DfuSeBootloader::Attach(UrbSink& sink) {
  sink_ = &sink;
  configuration_ = 0;
}

void DfuSeBootloader::Submit(Urb urb) {
  // The data stage goes the way bmRequestType says (USB 2.0 §9.3.1): a URB that disagrees, or a
  // request that answers with data although the host said it sends, is a request error, as is
  // anything for an endpoint but 0.
  const bool to_host = (urb.setup[0] & 0x80) != 0;
  const bool valid = urb.endpoint == 0 && to_host == (urb.direction == usbip::Direction::kIn);
  UrbResult r = valid ? Control(urb.setup, urb.out_data, urb.length) : Stall();
  if (!to_host && !r.in_data.empty()) r = Stall();
  if (sink_ != nullptr) sink_->Complete(urb, r);
}

UrbResult DfuSeBootloader::Control(const std::array<std::uint8_t, 8>& s,
                                   const std::vector<std::uint8_t>& out, std::uint32_t length) {
  const std::uint8_t type = s[0];
  const std::uint8_t request = s[1];
  const auto value = static_cast<std::uint16_t>(s[2] | (s[3] << 8));
  const auto index = static_cast<std::uint16_t>(s[4] | (s[5] << 8));
  const auto w_length = static_cast<std::uint16_t>(
      std::min<std::uint32_t>(static_cast<std::uint32_t>(s[6] | (s[7] << 8)), length));
  if ((type & 0x60) == 0x00) return Standard(request, value, w_length);
  if ((type & 0x60) == 0x20 && (type & 0x1F) == 0x01 && index == 0)
    return Dfu(request, value, out, w_length);
  return Stall();
}

std::vector<std::uint8_t> DfuSeBootloader::StringDescriptor(std::uint8_t index) const {
  if (index == 0) return {4, 3, 0x09, 0x04};  // English (United States)
  std::string text;
  switch (index) {
    case 1: text = "vibid"; break;
    case 2: text = "vibid DfuSe bootloader (emulated)"; break;
    case 3: text = serial_; break;
    case 4: text = dfu::kStm32f405FlashLayout; break;
    default: return {};
  }
  std::vector<std::uint8_t> d = {static_cast<std::uint8_t>(2 + 2 * text.size()), 3};
  for (char c : text) {
    d.push_back(static_cast<std::uint8_t>(c));
    d.push_back(0);
  }
  return d;
}

UrbResult DfuSeBootloader::Standard(std::uint8_t request, std::uint16_t value,
                                    std::uint16_t length) {
  switch (request) {
    case 0x00:  // GET_STATUS: self powered, no remote wakeup
      return Data({0x01, 0x00}, length);
    case 0x05:  // SET_ADDRESS: the exporting host already addressed the device
      return {};
    case 0x06: {  // GET_DESCRIPTOR
      const auto kind = static_cast<std::uint8_t>(value >> 8);
      if (kind == 1) return Data({kDeviceDescriptor.begin(), kDeviceDescriptor.end()}, length);
      if (kind == 2)
        return Data({kConfigurationDescriptor.begin(), kConfigurationDescriptor.end()}, length);
      if (kind == 3) {
        auto d = StringDescriptor(static_cast<std::uint8_t>(value & 0xFF));
        if (!d.empty()) return Data(std::move(d), length);
      }
      return Stall();
    }
    case 0x08: return Data({configuration_}, length);  // GET_CONFIGURATION
    case 0x09:                                         // SET_CONFIGURATION
      if (value > 1) return Stall();
      configuration_ = static_cast<std::uint8_t>(value);
      return {};
    case 0x0A: return Data({0}, length);                   // GET_INTERFACE
    case 0x0B: return value == 0 ? UrbResult{} : Stall();  // SET_INTERFACE: one alternate setting
    default: return Stall();
  }
}

void DfuSeBootloader::Fail(dfu::Status status) {
  status_ = status;
  state_ = State::kError;
}

UrbResult DfuSeBootloader::StallAndError() {
  Fail(dfu::Status::kErrStalledPkt);
  return Stall();
}

UrbResult DfuSeBootloader::Dfu(std::uint8_t request, std::uint16_t value,
                               const std::vector<std::uint8_t>& out, std::uint16_t length) {
  switch (static_cast<dfu::Request>(request)) {
    case dfu::Request::kDetach:  // already in the bootloader
      return {};
    case dfu::Request::kDnload: {
      if (state_ != State::kIdle && state_ != State::kDnloadIdle) return StallAndError();
      if (length == 0) {
        if (state_ != State::kDnloadIdle) return StallAndError();
        state_ = State::kManifestSync;
        return {};
      }
      if (out.size() < length) return StallAndError();
      block_ = value;
      block_data_.assign(out.begin(), out.begin() + length);
      download_done_ = false;
      state_ = State::kDnloadSync;
      UrbResult r;
      r.actual_length = length;
      return r;
    }
    case dfu::Request::kUpload: {
      if (state_ != State::kIdle && state_ != State::kUploadIdle) return StallAndError();
      if (value == 0) {
        state_ = State::kUploadIdle;
        return Data({Byte(DfuSeCommand::kGetCommands), Byte(DfuSeCommand::kSetAddressPointer),
                     Byte(DfuSeCommand::kErase), Byte(DfuSeCommand::kReadUnprotect)},
                    length);
      }
      if (value < dfu::kFirstDataBlock) return StallAndError();
      const std::uint32_t at =
          address_ + static_cast<std::uint32_t>(value - dfu::kFirstDataBlock) * kTransferSize;
      if (!FlashImage::Contains(at, 1)) {
        Fail(dfu::Status::kErrAddress);
        return Stall();
      }
      const std::size_t n =
          std::min<std::size_t>(length, FlashImage::kBytes - (at - FlashImage::kBase));
      std::vector<std::uint8_t> bytes(n);
      (void)flash_.Read(at, bytes);
      // A short block ends the upload (DFU 1.1 §6.2).
      state_ = n < length ? State::kIdle : State::kUploadIdle;
      return Data(std::move(bytes), length);
    }
    case dfu::Request::kGetStatus: {
      // Six bytes, or fewer if the host asked for fewer (a device never sends more than wLength).
      UrbResult r = GetStatus();
      if (r.in_data.size() > length) r.in_data.resize(length);
      r.actual_length = static_cast<std::uint32_t>(r.in_data.size());
      return r;
    }
    case dfu::Request::kClrStatus:
      if (state_ != State::kError) return StallAndError();
      status_ = dfu::Status::kOk;
      state_ = State::kIdle;
      return {};
    case dfu::Request::kGetState: return Data({static_cast<std::uint8_t>(state_)}, length);
    case dfu::Request::kAbort:
      if (state_ == State::kError || state_ == State::kDnBusy || state_ == State::kManifest)
        return StallAndError();
      state_ = State::kIdle;
      return {};
    default: return StallAndError();
  }
}

void DfuSeBootloader::ExecuteDownload() {
  poll_timeout_ms_ = kWritePollMs;
  if (block_ == 0) {
    const auto command = static_cast<DfuSeCommand>(block_data_[0]);
    if (command == DfuSeCommand::kSetAddressPointer && block_data_.size() == 5) {
      const std::uint32_t a = Le32(block_data_, 1);
      if (!FlashImage::Contains(a, 1)) return Fail(dfu::Status::kErrAddress);
      address_ = a;
      return;
    }
    if (command == DfuSeCommand::kErase && block_data_.size() == 1) {
      for (int s = 0; s < FlashImage::kSectorCount; ++s) (void)flash_.EraseSector(s);
      poll_timeout_ms_ = kMassErasePollMs;
      return;
    }
    if (command == DfuSeCommand::kErase && block_data_.size() == 5) {
      const auto sector = FlashImage::SectorOf(Le32(block_data_, 1));
      if (!sector) return Fail(dfu::Status::kErrAddress);
      if (!flash_.EraseSector(*sector)) return Fail(dfu::Status::kErrErase);
      poll_timeout_ms_ = kSectorErasePollMs;
      return;
    }
    if (command == DfuSeCommand::kReadUnprotect && block_data_.size() == 1)
      return;  // nothing is protected
    return Fail(dfu::Status::kErrTarget);
  }
  if (block_ < dfu::kFirstDataBlock) return Fail(dfu::Status::kErrTarget);
  const std::uint32_t at =
      address_ + static_cast<std::uint32_t>(block_ - dfu::kFirstDataBlock) * kTransferSize;
  if (!FlashImage::Contains(at, block_data_.size())) return Fail(dfu::Status::kErrAddress);
  if (!flash_.Program(at, block_data_)) return Fail(dfu::Status::kErrVerify);
}

UrbResult DfuSeBootloader::GetStatus() {
  std::uint32_t poll_ms = 0;
  State reported = state_;
  switch (state_) {
    case State::kDnloadSync:
      if (!download_done_) {
        ExecuteDownload();
        download_done_ = true;
        if (state_ == State::kError) {
          reported = state_;
          break;
        }
        // The operation ran: dfuDNBUSY for its poll time, then back to dfuDNLOAD-SYNC whose next
        // GETSTATUS reports the block complete.
        reported = State::kDnBusy;
        poll_ms = poll_timeout_ms_;
      } else {
        state_ = State::kDnloadIdle;
        reported = state_;
      }
      break;
    case State::kManifestSync:
      // Not manifestation tolerant: report dfuMANIFEST, then leave for the application.
      reported = State::kManifest;
      state_ = State::kManifestWaitReset;
      leave_ = true;
      break;
    default: break;
  }
  UrbResult r;
  r.in_data.resize(dfu::kStatusReplyBytes);
  dfu::Encode(dfu::StatusReply{status_, poll_ms, reported},
              std::span<std::uint8_t, dfu::kStatusReplyBytes>(r.in_data));
  r.actual_length = dfu::kStatusReplyBytes;
  return r;
}

}  // namespace vibid::emu
