// The emulator in its default, board-faithful mode (the board's 96 KiB log, one 64-byte report
// per 1 ms simulated frame), measured end to end through the host's own device layer
// (vibid::device::Connection over the USB/IP transport) against an emulator running in a thread
// exactly as vibid-emu does.
//
// 1. A streamed acquisition within the link budget, as `vibid acquire` runs it: a calibration
//    carrying an observer designed for the built-in 2-DOF rig is committed, the observer started,
//    and 40 s at 5 kHz log load cell 1, accelerometer 2 and d_hat (8-byte records, 6 per report:
//    6000 records/s on the link for 5000 made). Wall speed (simulated s per wall s, target >= 20x),
//    records, drops (0).
// 2. Sustained link use beyond the budget: 10 s at 10 kHz of load cell 1 and both accelerometers
//    (6-byte records, 9 per 58-byte stream data payload: 9000 records/s on the link for 10 000
//    made), so the link always has a report to send: reports per frame, payload bytes and record
//    bytes per second against the link's 64 000 B/s, in simulated time.
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
    std::fprintf(stderr, "observer design failed: %s %s\n", design.message.c_str(),
                 design.fixed.message.c_str());
    std::exit(1);
  }
  wire::CalibrationRecord r;
  r.dof_count = 2;
  r.mass_kg[0] = static_cast<float>(p.m1_kg);
  r.mass_kg[wire::kMaxDof + 1] = static_cast<float>(p.m2_kg);
  r.channels[0] = Scaling(wire::Unit::kNewton, 1, static_cast<float>(rig.load_cells[0].range));
  r.channels[1] = Scaling(wire::Unit::kNewton, 1, static_cast<float>(rig.load_cells[1].range));
  r.channels[2] =
      Scaling(wire::Unit::kMeterPerSecond2, 0, static_cast<float>(rig.accelerometers[0].range));
  r.channels[3] =
      Scaling(wire::Unit::kMeterPerSecond2, 1, static_cast<float>(rig.accelerometers[1].range));
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

wire::AcqConfigureRequest Acquisition() {
  wire::AcqConfigureRequest c;
  c.sample_period_us = 200;
  c.channel_mask = 0b001001;  // load cell 1, accelerometer 2 (the observer's inputs)
  c.flags = wire::kAcqFlagLogDob | wire::kAcqFlagStream;
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
    c.Configure(Acquisition());
    c.DobControl(true);

    // 1. Within the budget, streamed.
    std::uint64_t sim_start = emulator.SimulatedUs();
    auto started = Clock::now();
    const device::LogPull pull = c.AcquireStreamed();
    double wall_s = std::chrono::duration<double>(Clock::now() - started).count();
    double sim_s = static_cast<double>(emulator.SimulatedUs() - sim_start) * 1e-6;
    if (pull.records.size() != kRecords) Fail("the stream did not bring every record");
    const bool observed = std::any_of(pull.records.begin(), pull.records.end(),
                                      [](const wire::LogRecord& r) { return r.d_hat != 0; });
    if (!observed) Fail("d_hat stayed 0: the observer did not run");
    const double speed = sim_s / wall_s;
    std::printf(
        "emulator speed (board-faithful): %.1f simulated s in %.3f wall s = %.1fx real time "
        "(5 kHz, 2-DOF rig, DOB running, %zu records streamed, %u dropped)\n",
        sim_s, wall_s, speed, pull.records.size(), pull.trailer.dropped_records);
    if (pull.trailer.dropped_records != 0) rc = 1;
    if (speed < 20.0) rc = 1;

    // 2. Beyond the budget: the link never idles while the log holds records.
    wire::AcqConfigureRequest fast;
    fast.sample_period_us = 100;
    fast.channel_mask = 0b001101;
    fast.flags = wire::kAcqFlagStream;
    fast.record_limit = 100000;  // 10 s at 10 kHz
    c.Configure(fast);
    const std::uint64_t reports_before = c.counters().reports;
    sim_start = emulator.SimulatedUs();
    started = Clock::now();
    const device::LogPull flood = c.AcquireStreamed();
    wall_s = std::chrono::duration<double>(Clock::now() - started).count();
    sim_s = static_cast<double>(emulator.SimulatedUs() - sim_start) * 1e-6;
    const double reports = static_cast<double>(c.counters().reports - reports_before);
    const double record_bytes = 6.0;
    const double records = static_cast<double>(flood.records.size());
    const double payload =
        records * record_bytes + (reports - 2.0) * 4.0;  // records + one tick per data report
    std::printf(
        "link use beyond the budget (10 kHz, load cell and two accelerometers, 6-byte records): "
        "%.0f reports in %.3f simulated s "
        "= %.3f reports per 1 ms frame; payload %.0f B/s = %.1f %% of 64000 B/s (records alone "
        "%.1f %%); "
        "%.0f records kept, %u dropped; %.1fx real time\n",
        reports, sim_s, reports / (sim_s * 1000.0), payload / sim_s,
        100.0 * payload / sim_s / 64000.0, 100.0 * records * record_bytes / sim_s / 64000.0,
        records, flood.trailer.dropped_records, sim_s / wall_s);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "emu_speed: %s\n", e.what());
    rc = 1;
  }
  stop = true;
  loop.join();
  return rc;
}
