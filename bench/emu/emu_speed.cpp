// Emulator speed and log-pull throughput, measured end to end through the host's own device
// layer (vibid::device::Connection over the USB/IP transport) against an emulator running in a
// thread exactly as vibid-emu does (USB/IP server, core, rig, default 4 MiB log, full speed).
//
// 1. Speed: a calibration carrying an observer designed for the built-in 2-DOF rig is uploaded
//    and committed, the observer is started (dob-control) and a 40 s acquisition at 5 kHz logs
//    load cell 1, accelerometer 2 and d_hat (16-byte records; shaker at 16 Hz plus a hand push).
//    Nobody pulls meanwhile, so the log (262144 slots) never fills and simulated time never waits
//    for a host: simulated seconds per wall second of the sampling itself. Target >= 20x.
// 2. Throughput: the finished log pulled from record 0 (MB/s, records/s), next to the data rate
//    the emulator produced it at (records/s x record bytes at the measured speed) and the rate a
//    board produces it at (5 kHz x 16 B, real time).
// 3. Acquire while pulling, as `vibid acquire` does: the back-pressure lets the pull set the pace;
//    the effective speed and the drop count (0) are reported.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>

#include "emulator.hpp"
#include "vibid/device/connection.hpp"
#include "vibid/device/usbip_transport.hpp"
#include "vibid/dob/chain_plant.hpp"
#include "vibid/dob/design.hpp"
#include "vibid/shared/wire/calibration_record.hpp"

namespace {

using namespace vibid;
using Clock = std::chrono::steady_clock;

// Channel scaling of the built-in rig's converters: 12-bit codes centred at 2048, 2048 codes to
// full scale, so one code is 2^31 / 2^11 = 2^20 in Q31 of the full scale.
wire::ChannelScaling Scaling(wire::Unit unit, std::uint8_t dof, float full_scale) {
  return wire::ChannelScaling{2048, 1 << 20, 0, unit, dof, full_scale};
}

std::array<std::uint8_t, wire::kCalRecordBytes> RecordWithObserver(const emu::RigSpec& rig) {
  const model::Model truth = rig.Truth();
  dob::ChainParameters p;
  p.m1_kg = truth.m_kg(0, 0);
  p.m2_kg = truth.m_kg(1, 1);
  p.k1_n_per_m = rig.springs_n_per_m[0];
  p.k2_n_per_m = rig.springs_n_per_m[1];
  p.c1_ns_per_m = rig.dampers_ns_per_m[0];
  p.c2_ns_per_m = rig.dampers_ns_per_m[1];
  dob::DobOptions o;  // the source's Q: N = 5, r = 4, tau = 2 ms
  o.fs_hz = 5000.0;
  o.sensor = dob::SensorKind::kAcceleration;
  o.force_full_scale_n = rig.load_cells[0].range;
  o.sensor_full_scale = rig.accelerometers[1].range;
  const dob::DobDesign design = dob::DesignObserver(dob::ChainPlantForceOnM2(p), o);
  if (!design.stable || !design.fixed.ok) {
    std::fprintf(stderr, "observer design failed: %s %s\n", design.message.c_str(), design.fixed.message.c_str());
    std::exit(1);
  }
  wire::CalibrationRecord r;
  r.dof_count = 2;
  r.mass_kg = {static_cast<float>(p.m1_kg), 0.0f, 0.0f, static_cast<float>(p.m2_kg)};
  r.channels[0] = Scaling(wire::Unit::kNewton, 1, static_cast<float>(rig.load_cells[0].range));
  r.channels[1] = Scaling(wire::Unit::kNewton, 1, static_cast<float>(rig.load_cells[1].range));
  r.channels[2] = Scaling(wire::Unit::kMeterPerSecond2, 0, static_cast<float>(rig.accelerometers[0].range));
  r.channels[3] = Scaling(wire::Unit::kMeterPerSecond2, 1, static_cast<float>(rig.accelerometers[1].range));
  r.flags |= wire::kCalFlagHasDob;
  for (std::size_t i = 0; i < design.fixed.description.input_count; ++i) {
    const auto kind = design.fixed.description.input_kind[i];
    r.dob_input_channel[i] = kind == fixed::InputKind::kForce ? 0 : 3;
  }
  fixed::EncodeDescription(design.fixed.description, r.dob);
  std::array<std::uint8_t, wire::kCalRecordBytes> bytes{};
  wire::EncodeCalibrationRecord(r, bytes);
  return bytes;
}

constexpr std::uint32_t kRecords = 200000;  // 40 s at 5 kHz
constexpr double kPeriodS = 200e-6;

wire::AcqConfigureRequest Acquisition() {
  wire::AcqConfigureRequest c;
  c.sample_period_us = 200;
  c.channel_mask = 0b001001;  // load cell 1, accelerometer 2 (the observer's inputs)
  c.flags = wire::kAcqFlagLogDob;
  c.record_limit = kRecords;
  return c;
}

[[noreturn]] void Fail(const char* what) {
  std::fprintf(stderr, "emu_speed: %s\n", what);
  std::exit(1);
}

}  // namespace

int main() {
  emu::EmulatorOptions options;
  options.port = 0;
  options.seed = 1;
  emu::Emulator emulator(options);
  std::atomic<bool> stop{false};
  std::thread loop([&] { emulator.Run(stop); });
  int rc = 0;
  try {
    device::Connection c(device::UsbipDevice::Open("127.0.0.1", emulator.port()));
    const auto record = RecordWithObserver(options.rig);
    c.CalPut(record);
    c.CalCommit();
    const std::array<float, 4> shaker{16, 10, 10, 0};
    c.SelectScenario("shaker", shaker);
    const wire::AcqConfigureResponse layout = c.Configure(Acquisition());
    const double record_bytes = layout.record_bytes;
    c.DobControl(true);

    // 1. Sampling speed, nobody pulling.
    c.StartAcquisition();
    const auto started = Clock::now();
    wire::StatusResponse st = c.GetStatus();
    if (st.dob_running != 1) Fail("the observer is not running");
    while (st.acq_state != wire::AcqState::kDone) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      st = c.GetStatus();
    }
    const double wall_s = std::chrono::duration<double>(Clock::now() - started).count();
    const double sim_s = static_cast<double>(st.ticks) * kPeriodS;
    const double speed = sim_s / wall_s;
    std::printf("emulator speed: %.1f simulated s in %.3f wall s = %.1fx real time "
                "(5 kHz, 2-DOF rig, DOB running, %u records logged, %u dropped, %u saturations)\n",
                sim_s, wall_s, speed, st.records_written, st.dropped_records, st.saturation_count);

    // 2. Pull throughput of the finished log.
    const auto pull_start = Clock::now();
    const device::LogPull pull = c.PullLog(0);
    const double pull_s = std::chrono::duration<double>(Clock::now() - pull_start).count();
    if (pull.records.size() != kRecords) Fail("the pull did not return the whole log");
    const bool observed = std::any_of(pull.records.begin(), pull.records.end(),
                                      [](const wire::LogRecord& r) { return r.d_hat != 0; });
    if (!observed) Fail("d_hat stayed 0: the observer did not run");
    const double bytes = static_cast<double>(pull.records.size()) * record_bytes;
    std::printf("log pull over USB/IP (vibid_device): %zu records of %.0f B in %.3f s = %.2f MB/s, %.0f records/s\n",
                pull.records.size(), record_bytes, pull_s, bytes / pull_s / 1e6,
                static_cast<double>(pull.records.size()) / pull_s);
    std::printf("  the emulator sampled it at %.2f MB/s (%.0f records/s); a board at 5 kHz produces %.3f MB/s\n",
                5000.0 * speed * record_bytes / 1e6, 5000.0 * speed, 5000.0 * record_bytes / 1e6);

    // 3. Acquire while pulling: the pull sets the pace.
    c.StartAcquisition();
    const auto follow_start = Clock::now();
    const device::LogPull followed = c.PullLog(0);
    const double follow_s = std::chrono::duration<double>(Clock::now() - follow_start).count();
    std::printf("acquire while pulling: %.1f simulated s in %.3f wall s = %.1fx real time, %zu records, %u dropped\n",
                static_cast<double>(kRecords) * kPeriodS, follow_s, static_cast<double>(kRecords) * kPeriodS / follow_s,
                followed.records.size(), followed.trailer.dropped_records);
    if (followed.trailer.dropped_records != 0) rc = 1;
    if (speed < 20.0) rc = 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "emu_speed: %s\n", e.what());
    rc = 1;
  }
  stop = true;
  loop.join();
  return rc;
}
