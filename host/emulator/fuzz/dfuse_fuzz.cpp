// Fuzzes the emulated DfuSe bootloader with control URBs as dfu-util and the host's flasher send
// them. The input is a script (FuzzedDataProvider): DFU class requests (DNLOAD of DfuSe commands
// and data blocks, UPLOAD, GETSTATUS, GETSTATE, CLRSTATUS, ABORT, DETACH) and standard requests,
// with fields picked from the values the protocol uses (addresses in and around the flash,
// blocks 0..n, lengths up to wTransferSize), now and then arbitrary; URBs to other endpoints.
// Invariants: every URB completes exactly once with its own sequence number; an IN answer never
// holds more than wLength nor the URB's buffer; GETSTATUS is six bytes and GETSTATE names the state
// the bootloader is in; a block that programmed without an error reads back as written.
#include <fuzzer/FuzzedDataProvider.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "dfuse_bootloader.hpp"
#include "flash_image.hpp"
#include "vibid/device/usb_control.hpp"

namespace {

using namespace vibid;
using emu::DfuSeBootloader;
using emu::FlashImage;

void Require(bool condition) {
  if (!condition) __builtin_trap();
}

struct Sink final : emu::UrbSink {
  void Complete(const emu::Urb& urb, const emu::UrbResult& result) override {
    ++completions;
    last_seqnum = urb.seqnum;
    last = result;
  }
  int completions = 0;
  std::uint32_t last_seqnum = 0;
  emu::UrbResult last;
};

FlashImage& Flash() {
  static FlashImage flash{""};
  return flash;
}

constexpr std::array<std::uint32_t, 9> kAddresses = {0x08000000u, 0x08004000u, 0x08008000u,
                                                     0x0800C000u, 0x08010000u, 0x08020000u,
                                                     0x080FF800u, 0x08100000u, 0x07FFFFFFu};

class Script {
 public:
  explicit Script(FuzzedDataProvider& in) : in_(in), dfu_(Flash(), Record(), "0123456789AB") {
    for (int s = 0; s < FlashImage::kSectorCount; ++s) Require(Flash().EraseSector(s));
    dfu_.Attach(sink_);
  }

  void Run() {
    for (int step = 0; step < 40 && in_.remaining_bytes() > 0; ++step) {
      switch (in_.ConsumeIntegralInRange<int>(0, 9)) {
        case 0: Command(); break;
        case 1:
        case 2: Block(); break;
        case 3:
        case 4: Dfu(3, 0, 6); break;  // GETSTATUS
        case 5: Dfu(5, 0, 1); break;  // GETSTATE
        case 6:
          Dfu(in_.PickValueInArray<std::uint8_t>({0, 4, 6, 7}), 0, 0);
          break;  // DETACH, CLRSTATUS, ABORT
        case 7: Upload(); break;
        case 8: Standard(); break;
        default: Arbitrary(); break;
      }
    }
  }

 private:
  static usbip::UsbDevice Record() {
    usbip::UsbDevice d;
    d.busid = "1-1";
    d.busnum = 1;
    d.devnum = 2;
    return d;
  }

  emu::UrbResult Submit(std::uint8_t endpoint, usbip::Direction direction,
                        const std::array<std::uint8_t, 8>& setup, std::uint32_t length,
                        std::vector<std::uint8_t> out) {
    emu::Urb urb;
    urb.seqnum = ++seqnum_;
    urb.endpoint = endpoint;
    urb.direction = direction;
    urb.setup = setup;
    urb.length = length;
    urb.out_data = std::move(out);
    const int before = sink_.completions;
    dfu_.Submit(urb);
    Require(sink_.completions == before + 1 && sink_.last_seqnum == seqnum_);
    const emu::UrbResult& r = sink_.last;
    const auto w_length = static_cast<std::uint32_t>(setup[6] | (setup[7] << 8));
    Require(r.in_data.size() <= std::min(w_length, length));
    Require(direction == usbip::Direction::kIn || r.in_data.empty());
    return r;
  }

  emu::UrbResult Dfu(std::uint8_t request, std::uint16_t value, std::uint16_t length,
                     std::vector<std::uint8_t> out = {}) {
    const bool to_host = request == 2 || request == 3 || request == 5;
    const std::array<std::uint8_t, 8> setup =
        device::Setup{static_cast<std::uint8_t>(to_host ? 0xA1 : 0x21), request, value, 0, length}
            .Bytes();
    // The URB's buffer is usually wLength long; sometimes shorter, as a broken client sends it.
    std::uint32_t buffer = length;
    if (in_.ConsumeIntegralInRange<int>(0, 15) == 15)
      buffer = in_.ConsumeIntegralInRange<std::uint32_t>(0, length);
    if (!to_host) out.resize(std::min<std::size_t>(out.size(), buffer));
    const emu::UrbResult r = Submit(0, to_host ? usbip::Direction::kIn : usbip::Direction::kOut,
                                    setup, buffer, std::move(out));
    if (r.status != usbip::kStatusOk) return r;
    if (request == 3 && buffer >= 6) {
      Require(r.in_data.size() == 6 && r.in_data[4] <= 10);
    }
    if (request == 5 && buffer >= 1) {
      Require(r.in_data.size() == 1 && r.in_data[0] == static_cast<std::uint8_t>(dfu_.state()));
    }
    return r;
  }

  // DNLOAD block 0: a DfuSe command; then GETSTATUS runs it.
  void Command() {
    std::vector<std::uint8_t> c;
    const std::uint32_t a =
        in_.ConsumeBool() ? in_.PickValueInArray(kAddresses) : in_.ConsumeIntegral<std::uint32_t>();
    switch (in_.ConsumeIntegralInRange<int>(0, 4)) {
      case 0:
        c = {0x21, static_cast<std::uint8_t>(a), static_cast<std::uint8_t>(a >> 8),
             static_cast<std::uint8_t>(a >> 16), static_cast<std::uint8_t>(a >> 24)};
        break;
      case 1: c = {0x41}; break;
      case 2:
        c = {0x41, static_cast<std::uint8_t>(a), static_cast<std::uint8_t>(a >> 8),
             static_cast<std::uint8_t>(a >> 16), static_cast<std::uint8_t>(a >> 24)};
        break;
      case 3: c = {0x92}; break;
      default:
        c = in_.ConsumeBytes<std::uint8_t>(in_.ConsumeIntegralInRange<std::size_t>(1, 8));
        break;
    }
    if (c.empty()) c = {0};
    const auto length = static_cast<std::uint16_t>(c.size());
    (void)Dfu(1, 0, length, c);
  }

  // DNLOAD block n >= 2 (data); checked after the two GETSTATUS that program it.
  void Block() {
    const auto block =
        static_cast<std::uint16_t>(in_.ConsumeBool() ? in_.ConsumeIntegralInRange<int>(2, 5)
                                                     : in_.ConsumeIntegral<std::uint16_t>());
    const std::uint16_t length =
        in_.PickValueInArray<std::uint16_t>({16, 256, DfuSeBootloader::kTransferSize, 0, 1, 2049});
    std::vector<std::uint8_t> data =
        in_.ConsumeBytes<std::uint8_t>(in_.ConsumeIntegralInRange<std::size_t>(0, 64));
    data.resize(length, 0x5A);
    const emu::UrbResult r = Dfu(1, block, length, data);
    // Blocks 0 and 1 are commands, not data: nothing to read back.
    if (r.status != usbip::kStatusOk || length == 0 || block < 2) return;
    // A URB buffer shorter than wLength carries that much of the block.
    data.resize(r.actual_length);
    (void)Dfu(3, 0, 6);
    const emu::UrbResult done = Dfu(3, 0, 6);
    if (done.status != usbip::kStatusOk || dfu_.state() == dfu::State::kError) return;
    if (dfu_.state() != dfu::State::kDnloadIdle) return;
    // Read back through the protocol, from the bootloader's own address pointer.
    if (Dfu(6, 0, 0).status != usbip::kStatusOk) return;
    const emu::UrbResult back = Dfu(2, block, length);
    if (back.status == usbip::kStatusOk && back.in_data.size() >= data.size()) {
      Require(std::equal(data.begin(), data.end(), back.in_data.begin()));
    }
  }

  void Upload() {
    const auto block =
        static_cast<std::uint16_t>(in_.ConsumeBool() ? in_.ConsumeIntegralInRange<int>(0, 5)
                                                     : in_.ConsumeIntegral<std::uint16_t>());
    const std::uint16_t length =
        in_.PickValueInArray<std::uint16_t>({4, 16, DfuSeBootloader::kTransferSize, 0, 0xFFFF});
    (void)Dfu(2, block, length);
  }

  void Standard() {
    // bmRequestType, bRequest, wValue; wLength is picked below.
    constexpr std::array<device::Setup, 10> kRequests = {{{0x80, 0x06, 0x0100},
                                                          {0x80, 0x06, 0x0200},
                                                          {0x80, 0x06, 0x0304},
                                                          {0x80, 0x06, 0x0309},
                                                          {0x80, 0x00, 0},
                                                          {0x80, 0x08, 0},
                                                          {0x00, 0x09, 1},
                                                          {0x00, 0x09, 2},
                                                          {0x81, 0x0A, 0},
                                                          {0x01, 0x0B, 1}}};
    device::Setup setup = in_.PickValueInArray(kRequests);
    setup.length = in_.PickValueInArray<std::uint16_t>({0, 1, 2, 9, 18, 64, 255});
    (void)Submit(0, setup.In() ? usbip::Direction::kIn : usbip::Direction::kOut, setup.Bytes(),
                 setup.length, {});
  }

  void Arbitrary() {
    std::array<std::uint8_t, 8> setup{};
    const auto bytes = in_.ConsumeBytes<std::uint8_t>(8);
    std::copy(bytes.begin(), bytes.end(), setup.begin());
    const std::uint8_t endpoint = in_.ConsumeIntegralInRange<std::uint8_t>(0, 2);
    const std::uint32_t length = in_.ConsumeIntegralInRange<std::uint32_t>(0, 4096);
    const bool to_host = in_.ConsumeBool();
    std::vector<std::uint8_t> out;
    if (!to_host) out = in_.ConsumeBytes<std::uint8_t>(length);
    (void)Submit(endpoint, to_host ? usbip::Direction::kIn : usbip::Direction::kOut, setup, length,
                 std::move(out));
  }

  FuzzedDataProvider& in_;
  Sink sink_;
  DfuSeBootloader dfu_;
  std::uint32_t seqnum_ = 0;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  Script script(in);
  script.Run();
  return 0;
}
