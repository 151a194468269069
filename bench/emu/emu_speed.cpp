// Emulator speed: simulated seconds per wall second at 5 kHz with the built-in 2-DOF rig and the
// DOB running, measured end to end. The emulator runs in its own thread exactly as vibid-emu
// does (USB/IP server, core, rig); a client over loopback uploads a calibration carrying an
// observer designed for the rig, starts a logged acquisition with d_hat (shaker at 16 Hz plus a
// hand push) and polls get-status until the record limit is reached. Then the log is pulled to
// report the USB/IP throughput.
#include <atomic>
#include <chrono>
#include <cstdio>
#include <thread>

#include "emulator.hpp"
#include "test_client.hpp"
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

}  // namespace

int main() {
  emu::EmulatorOptions options;
  options.port = 0;
  options.seed = 1;
  emu::Emulator emulator(options);
  std::atomic<bool> stop{false};
  std::thread loop([&] { emulator.Run(stop); });

  constexpr std::uint32_t kRecords = 200000;  // 40 s at 5 kHz, 16-byte records: 3.2 MB of log
  int rc = 0;
  {
    emu::testing::DeviceSession s(emulator.port());
    const Status cal = s.Calibrate(RecordWithObserver(options.rig));
    if (cal != Status::kOk) {
      std::fprintf(stderr, "calibration refused: status %d\n", static_cast<int>(cal));
      rc = 1;
    }
    s.Request(wire::Command::kSelectScenario, emu::testing::ScenarioOf("shaker", {16, 10, 10, 0}));
    wire::AcqConfigureRequest c;
    c.sample_period_us = 200;
    c.channel_mask = 0b001001;  // load cell 1, accelerometer 2
    c.flags = wire::kAcqFlagLogDob;
    c.record_limit = kRecords;
    const auto configured = s.Request(wire::Command::kAcqConfigure, c);
    const auto started_answer = s.Request(wire::Command::kAcqStart);
    if (rc == 0 && (configured.header.status != Status::kOk || started_answer.header.status != Status::kOk)) {
      std::fprintf(stderr, "acquisition refused\n");
      rc = 1;
    }
    const auto started = Clock::now();
    wire::StatusResponse st = s.GetStatus();
    while (rc == 0 && st.acq_state != wire::AcqState::kDone) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      st = s.GetStatus();
    }
    const double wall_s = std::chrono::duration<double>(Clock::now() - started).count();
    const double sim_s = static_cast<double>(st.ticks) * 200e-6;
    std::printf("emulator speed: %.1f simulated s in %.3f wall s = %.1fx real time "
                "(5 kHz, 2-DOF rig, DOB running, %u records logged, %u saturations)\n",
                sim_s, wall_s, sim_s / wall_s, st.records_written, st.saturation_count);

    const auto pull_start = Clock::now();
    const auto log = s.PullLog(16);
    const double pull_s = std::chrono::duration<double>(Clock::now() - pull_start).count();
    std::printf("log pull over USB/IP: %zu bytes in %.3f s = %.0f KiB/s (%.0f records/s)\n", log.size(), pull_s,
                static_cast<double>(log.size()) / 1024.0 / pull_s,
                static_cast<double>(log.size()) / 16.0 / pull_s);
  }
  stop = true;
  loop.join();
  return rc;
}
