// The emulator exported over loopback USB/IP, driven by a client as a host would: descriptors,
// configuration, HID reports through the interrupt endpoints, unlink, the scenario command, and
// a DfuSe download written byte for byte into the flash file.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <thread>

#include "emulator.hpp"
#include "test_client.hpp"
#include "vibid/fw/usb/descriptors.hpp"
#include "vibid/shared/board_profile.hpp"
#include "vibid/shared/wire/calibration_record.hpp"
#include "vibid/shared/wire/commands.hpp"

namespace vibid::emu {
namespace {

using testing::Req;
using testing::TestClient;
using usbip::Direction;
using namespace std::chrono_literals;

class EmulatorOverUsbIp : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("vibid_emu_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
    Start();
  }
  void TearDown() override {
    Stop();
    std::filesystem::remove_all(dir_);
  }
  void Start() {
    EmulatorOptions o;
    o.port = 0;
    o.flash_path = (dir_ / "flash.bin").string();
    o.seed = 7;
    emulator_ = std::make_unique<Emulator>(o);
    port_ = emulator_->port();
    stop_ = false;
    thread_ = std::thread([this] { emulator_->Run(stop_); });
  }
  void Stop() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
    emulator_.reset();
  }

  // The standard part of enumeration after the exporting host addressed the device.
  static void Configure(TestClient& c) {
    const auto r = c.Control(Req(0x00, 9, 1, 0, 0), 0);  // SET_CONFIGURATION 1
    ASSERT_EQ(r.status, 0);
  }

  // A request without a payload.
  static wire::Report Request(wire::Command command, std::uint16_t token) {
    wire::Report r{};
    EXPECT_EQ(wire::BuildReport(command, token, 0, 0, Status::kOk, {}, r), Status::kOk);
    return r;
  }

  // One request over the HID interrupt endpoints; returns the answer's report.
  static wire::Report Transact(TestClient& c, const wire::Report& request) {
    const std::uint32_t in = c.Submit(1, Direction::kIn, 64);
    const auto out = c.Wait(c.Submit(1, Direction::kOut, 64, {}, {request.begin(), request.end()}));
    EXPECT_EQ(out.status, 0);
    EXPECT_EQ(out.actual_length, 64u);
    const auto answer = c.Wait(in);
    EXPECT_EQ(answer.status, 0);
    wire::Report report{};
    EXPECT_EQ(answer.data.size(), 64u);
    std::copy_n(answer.data.begin(), std::min<std::size_t>(64, answer.data.size()), report.begin());
    return report;
  }

  std::filesystem::path dir_;
  std::unique_ptr<Emulator> emulator_;
  std::uint16_t port_ = 0;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

TEST_F(EmulatorOverUsbIp, DeviceListNamesTheBoard) {
  auto s = usbip::ConnectTcp("127.0.0.1", port_, 2000ms);
  const auto list = usbip::RequestDeviceList(s);
  ASSERT_EQ(list.size(), 1u);
  EXPECT_EQ(list[0].busid, "1-1");
  EXPECT_EQ(list[0].id_vendor, 0x1209);  // pid.codes
  EXPECT_EQ(list[0].id_product, fw::usb::kProductId);
  EXPECT_EQ(list[0].speed, usbip::Speed::kFull);
  ASSERT_EQ(list[0].interfaces.size(), 2u);
  EXPECT_EQ(list[0].interfaces[0].interface_class, 0x03);  // HID
  EXPECT_EQ(list[0].interfaces[1].interface_class, 0xFE);  // application specific: DFU run-time
  EXPECT_EQ(list[0].interfaces[1].interface_subclass, 0x01);
  EXPECT_EQ(list[0].interfaces[1].interface_protocol, 0x01);
}

TEST_F(EmulatorOverUsbIp, EnumeratesLikeABoard) {
  TestClient c(port_);
  EXPECT_EQ(c.device().devid(), 0x00010002u);

  // GET_DESCRIPTOR(device), USB 2.0 table 9-8, decoded by hand.
  const auto dev = c.Control(Req(0x80, 6, 0x0100, 0, 18), 18);
  ASSERT_EQ(dev.status, 0);
  ASSERT_EQ(dev.data.size(), 18u);
  EXPECT_EQ(dev.data[0], 18);    // bLength
  EXPECT_EQ(dev.data[1], 1);     // DEVICE
  EXPECT_EQ(dev.data[2], 0x00);  // bcdUSB 2.00
  EXPECT_EQ(dev.data[3], 0x02);
  EXPECT_EQ(dev.data[7], 64);    // bMaxPacketSize0
  EXPECT_EQ(dev.data[8], 0x09);  // idVendor 0x1209, little-endian
  EXPECT_EQ(dev.data[9], 0x12);
  EXPECT_EQ(dev.data[17], 1);  // bNumConfigurations
  EXPECT_TRUE(std::equal(dev.data.begin(), dev.data.end(), fw::usb::kDeviceDescriptor.begin()));

  // GET_DESCRIPTOR(configuration): the 9-byte header first, then wTotalLength (two packets).
  const auto head = c.Control(Req(0x80, 6, 0x0200, 0, 9), 9);
  ASSERT_EQ(head.data.size(), 9u);
  const std::uint16_t total = static_cast<std::uint16_t>(head.data[2] | (head.data[3] << 8));
  EXPECT_EQ(total, fw::usb::kConfigurationTotalSize);
  EXPECT_EQ(head.data[4], 2);  // bNumInterfaces
  const auto config = c.Control(Req(0x80, 6, 0x0200, 0, 255), 255);
  ASSERT_EQ(config.status, 0);
  ASSERT_EQ(config.data.size(), total);
  EXPECT_TRUE(std::equal(config.data.begin(), config.data.end(),
                         fw::usb::kConfigurationDescriptor.begin()));

  // A string: the serial number names the emulator and its seed.
  const auto serial = c.Control(Req(0x80, 6, 0x0303, 0x0409, 255), 255);
  ASSERT_EQ(serial.status, 0);
  ASSERT_GE(serial.data.size(), 8u);
  EXPECT_EQ(serial.data[1], 3);
  EXPECT_EQ(serial.data[2], 'E');
  EXPECT_EQ(serial.data[4], 'M');

  Configure(c);
  const auto cfg = c.Control(Req(0x80, 8, 0, 0, 1), 1);  // GET_CONFIGURATION
  ASSERT_EQ(cfg.data.size(), 1u);
  EXPECT_EQ(cfg.data[0], 1);

  // HID report descriptor (HID 1.11 §7.1.1: GET_DESCRIPTOR to the interface, type 0x22).
  const auto report = c.Control(Req(0x81, 6, 0x2200, 0, 255), 255);
  ASSERT_EQ(report.status, 0);
  ASSERT_EQ(report.data.size(), fw::usb::kHidReportDescriptor.size());
  EXPECT_EQ(report.data[0], 0x06);  // Usage Page (16-bit)
  EXPECT_EQ(report.data[1], 0x00);
  EXPECT_EQ(report.data[2], 0xFF);  // vendor page 0xFF00

  // SET_IDLE is accepted; an unknown descriptor type stalls (-EPIPE).
  EXPECT_EQ(c.Control(Req(0x21, 0x0A, 0, 0, 0), 0).status, 0);
  EXPECT_EQ(c.Control(Req(0x80, 6, 0x0900, 0, 9), 9).status, usbip::kStatusStall);
  // The endpoint-0 stall clears with the next SETUP.
  EXPECT_EQ(c.Control(Req(0x80, 6, 0x0100, 0, 18), 18).status, 0);
}

TEST_F(EmulatorOverUsbIp, PingAndInfoOverInterruptEndpoints) {
  TestClient c(port_);
  Configure(c);

  const std::array<std::uint8_t, 5> hello = {'h', 'e', 'l', 'l', 'o'};
  wire::Report ping{};
  ASSERT_EQ(wire::BuildReport(wire::Command::kPing, 0x1234, 0, 0, Status::kOk, hello, ping),
            Status::kOk);
  const wire::Report pong = Transact(c, ping);
  wire::Header h;
  ASSERT_EQ(wire::DecodeHeader(pong, h), Status::kOk);
  EXPECT_EQ(h.command, static_cast<std::uint8_t>(wire::Command::kPing));
  EXPECT_EQ(h.token, 0x1234);
  EXPECT_EQ(h.status, Status::kOk);
  EXPECT_NE(h.flags & wire::kFlagResponse, 0);
  const auto payload = wire::PayloadOf(pong);
  EXPECT_TRUE(std::equal(payload.begin(), payload.end(), hello.begin(), hello.end()));

  const wire::Report info_report = Transact(c, Request(wire::Command::kGetInfo, 7));
  wire::InfoResponse info;
  ASSERT_EQ(wire::Decode(wire::PayloadOf(info_report), info), Status::kOk);
  EXPECT_EQ(info.board_id, wire::BoardId::kEmulator);
  EXPECT_NE(info.capabilities & wire::kCapScenarioSelect, 0u);
  EXPECT_NE(info.capabilities & wire::kCapDfu, 0u);
  EXPECT_EQ(info.reset_cause, wire::ResetCause::kPowerOn);
  EXPECT_EQ(info.log_capacity_bytes, kBoardProfile.log_bytes);  // the board's, not more
  EXPECT_EQ(info.link_reports_per_s, kBoardProfile.link_reports_per_s);
}

TEST_F(EmulatorOverUsbIp, ScenarioCommand) {
  TestClient c(port_);
  Configure(c);
  auto select = [&](const char* name, std::array<float, 4> params) {
    wire::ScenarioRequest s;
    std::snprintf(s.name.data(), s.name.size(), "%s", name);
    s.params = params;
    wire::Report r{};
    EXPECT_EQ(wire::BuildReport(wire::Command::kSelectScenario, 1, 0, 0, Status::kOk, s, r),
              Status::kOk);
    wire::Header h;
    EXPECT_EQ(wire::DecodeHeader(Transact(c, r), h), Status::kOk);
    return h.status;
  };
  EXPECT_EQ(select("hammer", {2, 120, 1, 0}), Status::kOk);
  EXPECT_EQ(select("hammer", {1, 0, 0, 1}), Status::kOk);               // mass 1 alone
  EXPECT_EQ(select("hammer", {2, 0, 0, 1}), Status::kInvalidArgument);  // m2 is not on the rig then
  EXPECT_EQ(select("shaker", {16, 10, 5, 0}), Status::kOk);
  EXPECT_EQ(select("earthquake", {}), Status::kInvalidArgument);
}

TEST_F(EmulatorOverUsbIp, UnlinkCancelsAPendingInterruptIn) {
  TestClient c(port_);
  Configure(c);
  // Nothing to report: the IN URB pends (the device NAKs the host's polls).
  const std::uint32_t pending = c.Submit(1, Direction::kIn, 64);
  c.Drain(50ms);
  EXPECT_FALSE(c.Completed(pending));
  EXPECT_EQ(c.Unlink(pending), usbip::kStatusUnlinked);

  // The unlinked URB never completes: the next answer goes to the next IN URB.
  const wire::Report pong = Transact(c, Request(wire::Command::kPing, 99));
  wire::Header h;
  ASSERT_EQ(wire::DecodeHeader(pong, h), Status::kOk);
  EXPECT_EQ(h.token, 99);
  EXPECT_FALSE(c.Completed(pending));

  // Unlinking a URB that already completed answers status 0 (usbip_protocol.rst).
  const std::uint32_t done = c.Submit(0, Direction::kIn, 18, Req(0x80, 6, 0x0100, 0, 18));
  c.Wait(done);
  EXPECT_EQ(c.Unlink(done), 0);
}

TEST_F(EmulatorOverUsbIp, SecondImportIsRefusedWhileTheFirstHoldsTheDevice) {
  TestClient first(port_);
  auto s = usbip::ConnectTcp("127.0.0.1", port_, 2000ms);
  EXPECT_THROW(usbip::RequestImport(s, "1-1"), usbip::ProtocolError);
  auto other = usbip::ConnectTcp("127.0.0.1", port_, 2000ms);
  EXPECT_THROW(usbip::RequestImport(other, "2-1"), usbip::ProtocolError);
}

TEST_F(EmulatorOverUsbIp, DfuDetachReachesTheBootloader) {
  {
    TestClient app(port_);
    Configure(app);
    // DFU 1.1 DFU_DETACH to the run-time interface (1), wTimeout 1000 ms; bitWillDetach is set,
    // so the device leaves by itself after the status stage.
    EXPECT_EQ(app.Control(Req(0x21, 0, 1000, 1, 0), 0).status, 0);
    EXPECT_TRUE(app.Closed(2000ms));
  }
  TestClient boot(port_);
  EXPECT_EQ(boot.device().id_product, 0xDF11);
  const auto layout = boot.Control(Req(0x80, 6, 0x0304, 0x0409, 255), 255);  // iInterface string
  ASSERT_EQ(layout.status, 0);
  std::string text;
  for (std::size_t i = 2; i + 1 < layout.data.size(); i += 2)
    text.push_back(static_cast<char>(layout.data[i]));
  EXPECT_EQ(text, "@Internal Flash  /0x08000000/04*016Kg,01*064Kg,07*128Kg");
}

TEST_F(EmulatorOverUsbIp, CalibrationSurvivesARestartAndResetIsSoftware) {
  wire::CalibrationRecord r;
  r.dof_count = 2;
  r.created_unix_s = 1700000000;
  constexpr std::size_t n = wire::kMaxDof;  // row-major n x n blocks, zero beyond 2 x 2
  r.mass_kg[0] = 1.82f;
  r.mass_kg[n + 1] = 1.53f;
  r.stiffness_n_per_m[0] = 6280.0f;
  r.stiffness_n_per_m[1] = r.stiffness_n_per_m[n] = -2760.0f;
  r.stiffness_n_per_m[n + 1] = 2760.0f;
  r.channels[0] = {2048, 1 << 20, 0, wire::Unit::kNewton, 1, 500.0f};
  std::array<std::uint8_t, wire::kCalRecordBytes> bytes{};
  wire::EncodeCalibrationRecord(r, bytes);
  auto info_of = [](testing::DeviceSession& s) {
    wire::InfoResponse info;
    EXPECT_EQ(wire::Decode(s.Request(wire::Command::kGetInfo).payload, info), Status::kOk);
    return info;
  };
  {
    testing::DeviceSession s(port_);
    EXPECT_EQ(info_of(s).cal_state, wire::CalState::kUncalibrated);
    ASSERT_EQ(s.Calibrate(bytes), Status::kOk);
    EXPECT_EQ(s.Request(wire::Command::kReset).header.status, Status::kOk);
    EXPECT_TRUE(s.client().Closed(2000ms));
  }
  {
    testing::DeviceSession s(port_);
    const wire::InfoResponse info = info_of(s);
    EXPECT_EQ(info.reset_cause, wire::ResetCause::kSoftware);
    EXPECT_EQ(info.cal_state, wire::CalState::kCalibrated);
  }
  // A new emulator process on the same flash file boots calibrated, from power-on.
  Stop();
  Start();
  testing::DeviceSession s(port_);
  const wire::InfoResponse info = info_of(s);
  EXPECT_EQ(info.reset_cause, wire::ResetCause::kPowerOn);
  EXPECT_EQ(info.cal_state, wire::CalState::kCalibrated);
  EXPECT_EQ(info.cal_crc,
            wire::ComputeCrc32(std::span<const std::uint8_t>(bytes).first(wire::kCalOffCrc)));
}

TEST_F(EmulatorOverUsbIp, GarbageDropsOnlyThatClient) {
  {
    auto s = usbip::ConnectTcp("127.0.0.1", port_, 2000ms);
    const std::array<std::uint8_t, 8> wrong_version = {0x01, 0x06, 0x80, 0x05, 0, 0, 0, 0};
    s.SendAll(wrong_version);
    std::array<std::uint8_t, 1> byte{};
    EXPECT_THROW(s.ReceiveExact(byte), usbip::IoError);  // closed without an answer
  }
  {
    TestClient c(port_);
    const std::array<std::uint8_t, usbip::kUrbHeaderBytes> junk{0, 0, 0, 9};
    c.socket().SendAll(junk);  // URB command 9 does not exist
    EXPECT_TRUE(c.Closed(2000ms));
  }
  // The device was released with the dropped client: the next import works.
  TestClient again(port_);
  EXPECT_EQ(again.Control(Req(0x80, 6, 0x0100, 0, 18), 18).status, 0);
}

// DfuSe: GETSTATUS after a download runs it (dfuDNBUSY), the next one reports dfuDNLOAD-IDLE.
void DfuSeBlock(TestClient& c, std::uint16_t block, const std::vector<std::uint8_t>& data) {
  ASSERT_EQ(c.Control(Req(0x21, 1, block, 0, static_cast<std::uint16_t>(data.size())),
                      static_cast<std::uint32_t>(data.size()), data)
                .status,
            0);
  const auto busy = c.Control(Req(0xA1, 3, 0, 0, 6), 6);
  ASSERT_EQ(busy.data.size(), 6u);
  ASSERT_EQ(busy.data[0], 0) << "bStatus";
  ASSERT_EQ(busy.data[4], 4) << "dfuDNBUSY";
  const auto idle = c.Control(Req(0xA1, 3, 0, 0, 6), 6);
  ASSERT_EQ(idle.data[4], 5) << "dfuDNLOAD-IDLE";
}

std::vector<std::uint8_t> Command(std::uint8_t cmd, std::uint32_t address) {
  return {cmd, static_cast<std::uint8_t>(address), static_cast<std::uint8_t>(address >> 8),
          static_cast<std::uint8_t>(address >> 16), static_cast<std::uint8_t>(address >> 24)};
}

TEST_F(EmulatorOverUsbIp, DfuSeDownloadLandsInTheFlashFile) {
  constexpr std::uint32_t kImageAddress = 0x08010000;  // sector 4, where the board's code starts
  std::vector<std::uint8_t> image(5000);
  for (std::size_t i = 0; i < image.size(); ++i)
    image[i] = static_cast<std::uint8_t>((i * 31 + 7) ^ (i >> 8));

  {
    // enter-DFU over HID: answered, then the device re-enumerates as the bootloader.
    TestClient app(port_);
    Configure(app);
    wire::Header h;
    ASSERT_EQ(wire::DecodeHeader(Transact(app, Request(wire::Command::kEnterDfu, 5)), h),
              Status::kOk);
    EXPECT_EQ(h.status, Status::kOk);
    EXPECT_TRUE(app.Closed(2000ms));
  }
  {
    TestClient boot(port_);
    EXPECT_EQ(boot.device().id_vendor, 0x0483);
    EXPECT_EQ(boot.device().id_product, 0xDF11);
    // DFU functional descriptor (DFU 1.1 table 4.2) at the end of the configuration.
    const auto config = boot.Control(Req(0x80, 6, 0x0200, 0, 255), 255);
    ASSERT_EQ(config.data.size(), 27u);
    EXPECT_EQ(config.data[18 + 1], 0x21);
    EXPECT_EQ(config.data[18 + 5] | (config.data[18 + 6] << 8), 2048);    // wTransferSize
    EXPECT_EQ(config.data[18 + 7] | (config.data[18 + 8] << 8), 0x011A);  // DfuSe
    ASSERT_EQ(boot.Control(Req(0x00, 9, 1, 0, 0), 0).status, 0);
    const auto state = boot.Control(Req(0xA1, 5, 0, 0, 1), 1);
    ASSERT_EQ(state.data.size(), 1u);
    EXPECT_EQ(state.data[0], 2);  // dfuIDLE

    DfuSeBlock(boot, 0, Command(0x41, kImageAddress));  // erase sector 4
    DfuSeBlock(boot, 0, Command(0x21, kImageAddress));  // address pointer
    for (std::size_t at = 0, block = 2; at < image.size(); at += 2048, ++block) {
      const std::size_t n = std::min<std::size_t>(2048, image.size() - at);
      DfuSeBlock(boot, static_cast<std::uint16_t>(block),
                 std::vector<std::uint8_t>(image.begin() + static_cast<std::ptrdiff_t>(at),
                                           image.begin() + static_cast<std::ptrdiff_t>(at + n)));
    }
    // Programming over bytes that are not erased fails verification: dfuERROR, errVERIFY.
    ASSERT_EQ(boot.Control(Req(0x21, 1, 2, 0, 4), 4, {0xFF, 0xFF, 0xFF, 0xFF}).status, 0);
    const auto verify = boot.Control(Req(0xA1, 3, 0, 0, 6), 6);
    EXPECT_EQ(verify.data[0], 0x07);                              // errVERIFY
    EXPECT_EQ(verify.data[4], 10);                                // dfuERROR
    EXPECT_EQ(boot.Control(Req(0x21, 4, 0, 0, 0), 0).status, 0);  // CLRSTATUS

    // Read back with UPLOAD from the pointer (ABORT to dfuIDLE first).
    ASSERT_EQ(boot.Control(Req(0x21, 6, 0, 0, 0), 0).status, 0);
    std::vector<std::uint8_t> back;
    for (std::uint16_t block = 2; back.size() < image.size(); ++block) {
      const auto up = boot.Control(Req(0xA1, 2, block, 0, 2048), 2048);
      ASSERT_EQ(up.status, 0);
      back.insert(back.end(), up.data.begin(), up.data.end());
    }
    back.resize(image.size());
    EXPECT_EQ(back, image);

    // Leave: zero-length DNLOAD, GETSTATUS answers dfuMANIFEST, the application comes back.
    ASSERT_EQ(boot.Control(Req(0x21, 6, 0, 0, 0), 0).status, 0);
    DfuSeBlock(boot, 0, Command(0x21, 0x08000000));
    ASSERT_EQ(boot.Control(Req(0x21, 1, 0, 0, 0), 0).status, 0);
    const auto manifest = boot.Control(Req(0xA1, 3, 0, 0, 6), 6);
    EXPECT_EQ(manifest.data[4], 7);  // dfuMANIFEST
    EXPECT_TRUE(boot.Closed(2000ms));
  }
  {
    TestClient app(port_);
    EXPECT_EQ(app.device().id_vendor, 0x1209);
  }
  Stop();
  std::ifstream in(dir_ / "flash.bin", std::ios::binary);
  const std::vector<std::uint8_t> flash((std::istreambuf_iterator<char>(in)),
                                        std::istreambuf_iterator<char>());
  ASSERT_EQ(flash.size(), 1024u * 1024u);
  EXPECT_TRUE(std::equal(image.begin(), image.end(), flash.begin() + 0x10000));
  // The rest of sector 4 stays erased; the calibration sectors were not touched.
  EXPECT_EQ(flash[0x10000 + image.size()], 0xFF);
  EXPECT_EQ(flash[0x8000], 0xFF);
}

// Two emulators with the same seed, the same commands: the same logged samples, byte for byte,
// though the loop's timing differs run to run. A third with another seed differs.
std::vector<std::uint8_t> HammerRun(std::uint64_t seed, std::uint64_t* ticks) {
  EmulatorOptions o;
  o.port = 0;
  o.seed = seed;
  Emulator emu(o);
  std::atomic<bool> stop{false};
  std::thread loop([&] { emu.Run(stop); });
  std::vector<std::uint8_t> log;
  {
    testing::DeviceSession s(emu.port());
    EXPECT_EQ(
        s.Request(wire::Command::kSelectScenario, testing::ScenarioOf("hammer", {2, 100, 0.25f, 0}))
            .header.status,
        Status::kOk);
    wire::AcqConfigureRequest c;
    c.sample_period_us = 200;
    c.channel_mask = wire::kAllChannelsMask;
    c.flags = wire::kAcqFlagStream;
    c.record_limit = 10000;  // 2 s at 5 kHz; the link carries 3000 of the 5000 records/s, the
                             // rest waits in the log (4000 of its 4915 records at the end)
    EXPECT_EQ(s.Request(wire::Command::kAcqConfigure, c).header.status, Status::kOk);
    log = s.StreamAcquisition(16);
    const wire::StatusResponse st = s.GetStatus();
    EXPECT_EQ(st.acq_state, wire::AcqState::kDone);
    EXPECT_EQ(st.dropped_records, 0u);
    *ticks = st.ticks;
  }
  stop = true;
  loop.join();
  return log;
}

TEST(EmulatorDeterminism, SameSeedSameLog) {
  std::uint64_t ticks_a = 0, ticks_b = 0, ticks_c = 0;
  const auto a = HammerRun(21, &ticks_a);
  const auto b = HammerRun(21, &ticks_b);
  const auto c = HammerRun(22, &ticks_c);
  // 10000 records of four u16 12.4 codes and two i32 counts.
  ASSERT_EQ(a.size(), 10000u * 16u);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  // The hits are in the log: load cell 1 leaves its zero code (2048) at 0.5 s, sample 2500.
  auto force_code = [&](std::size_t record) {
    const std::uint8_t* p = a.data() + record * 16;
    return static_cast<std::int32_t>(p[0] | (p[1] << 8)) / 16;
  };
  std::int32_t peak = 0;
  for (std::size_t i = 2490; i < 2520; ++i) peak = std::max(peak, force_code(i) - 2048);
  EXPECT_GT(peak, 200);  // ≥ 60 N on ±500 N over ±2048 codes
  EXPECT_GE(ticks_a, 10000u);
}

}  // namespace
}  // namespace vibid::emu
