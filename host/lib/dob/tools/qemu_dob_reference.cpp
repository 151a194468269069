// vibid_qemu_dob_reference: the host half of the QEMU image's DOB check.
//
//   vibid_qemu_dob_reference record OUT.bin
//       Designs a disturbance observer for the reference rig (1 DOF, m = 2 kg, k = 8 kN/m,
//       c = 6 N s/m; force on load cell 1, acceleration on accelerometer 1; 5 kHz) with the host
//       DOB library, quantizes it and writes the calibration record (kCalRecordBytes) to upload.
//   vibid_qemu_dob_reference replay RECORD.bin FRAMES.txt
//       Prints d_hat (Q31) for each frame (six raw integers per line): the record's channel
//       scaling (wire::ScaleChannel) and the shared fixed-point kernel (fixed::DobFilter),
//       compiled for the host, on the same raw samples the image received.
//
// Exit codes: 0 done, 1 bad input or a failed design (one-line message on stderr). Built with the
// embedded rules of the wire code it links (no exceptions), so errors are return values here.
#include <array>
#include <bit>
#include <cstdint>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "vibid/dob/design.hpp"
#include "vibid/shared/fixed/dob_filter.hpp"
#include "vibid/shared/fixed/filter_description.hpp"
#include "vibid/shared/wire/calibration_record.hpp"

namespace {

using namespace vibid;

constexpr double kMassKg = 2.0;
constexpr double kStiffnessNPerM = 8000.0;
constexpr double kDampingNsPerM = 6.0;
constexpr std::uint8_t kForceChannel = 0;  // wire::Channel::kForce1
constexpr std::uint8_t kAccelChannel = 2;  // wire::Channel::kAccel1
/// 12-bit converter centred at mid-scale: (raw - 2048) * 2^20 spans the Q31 full scale.
constexpr std::int32_t kAdcMid = 2048;
constexpr std::int32_t kAdcGain = 1 << 20;

int Fail(const std::string& message) {
  std::cerr << "vibid_qemu_dob_reference: " << message << '\n';
  return 1;
}

/// @returns false with a message when the design or its quantization is refused.
bool MakeRecord(wire::CalibrationRecord& r, std::string& message) {
  dob::NominalPlant plant;
  plant.receptance_num = Eigen::VectorXd::Constant(1, 1.0);
  plant.receptance_den = Eigen::Vector3d(kMassKg, kDampingNsPerM, kStiffnessNPerM);
  dob::DobOptions options;
  options.sensor = dob::SensorKind::kAcceleration;
  options.input_dof = 0;
  options.output_dof = 0;
  options.fs_hz = 5000.0;
  const dob::DobDesign design = dob::DesignObserver(plant, options);
  if (!design.stable || !design.fixed.ok) {
    message = "reference DOB design failed: " + design.message + design.fixed.message;
    return false;
  }
  const fixed::FilterDescription& d = design.fixed.description;

  r = wire::CalibrationRecord{};
  r.dof_count = 1;
  r.flags = wire::kCalFlagHasDob;
  const std::string label = "qemu reference rig";
  std::copy(label.begin(), label.end(), r.label.begin());
  r.mass_kg[0] = static_cast<float>(kMassKg);
  r.damping_ns_per_m[0] = static_cast<float>(kDampingNsPerM);
  r.stiffness_n_per_m[0] = static_cast<float>(kStiffnessNPerM);
  for (std::size_t i = 0; i < d.input_count; ++i) {
    const bool force = d.input_kind[i] == fixed::InputKind::kForce;
    const std::uint8_t channel = force ? kForceChannel : kAccelChannel;
    wire::ChannelScaling& s = r.channels[channel];
    s.offset_counts = kAdcMid;
    s.gain = kAdcGain;
    s.gain_shift = 0;
    s.unit = force ? wire::Unit::kNewton : wire::Unit::kMeterPerSecond2;
    s.dof = 0;
    s.full_scale = std::bit_cast<float>(d.input_full_scale_bits[i]);
    r.dob_input_channel[i] = channel;
  }
  fixed::EncodeDescription(d, r.dob);
  return true;
}

int Record(const std::string& out_path) {
  wire::CalibrationRecord record;
  std::string message;
  if (!MakeRecord(record, message)) return Fail(message);
  std::array<std::uint8_t, wire::kCalRecordBytes> bytes{};
  wire::EncodeCalibrationRecord(record, bytes);
  std::ofstream out(out_path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
  if (!out) return Fail("cannot write " + out_path);
  return 0;
}

int Replay(const std::string& record_path, const std::string& frames_path) {
  std::ifstream in(record_path, std::ios::binary);
  if (!in) return Fail("cannot open " + record_path);
  const std::vector<std::uint8_t> bytes{std::istreambuf_iterator<char>(in),
                                        std::istreambuf_iterator<char>()};
  wire::CalibrationRecord record;
  if (wire::DecodeCalibrationRecord(bytes, record) != Status::kOk) {
    return Fail(record_path + ": not a valid calibration record");
  }
  fixed::FilterDescription description;
  if (fixed::DecodeDescription(record.dob, description) != Status::kOk) {
    return Fail(record_path + ": the DOB description does not decode");
  }
  fixed::DobFilter filter;
  if (filter.Init(description) != Status::kOk)
    return Fail(record_path + ": the DOB does not validate");

  std::ifstream frames(frames_path);
  if (!frames) return Fail("cannot open " + frames_path);
  std::string line;
  int line_number = 0;
  std::uint32_t clips = 0;
  while (std::getline(frames, line)) {
    ++line_number;
    std::istringstream fields(line);
    std::array<std::int32_t, wire::kChannelCount> raw{};
    for (auto& v : raw) {
      if (!(fields >> v))
        return Fail(frames_path + ":" + std::to_string(line_number) + ": expected six integers");
    }
    fixed::InputFrame inputs{};
    for (std::size_t i = 0; i < inputs.size(); ++i) {
      const std::uint8_t c = record.dob_input_channel[i];
      if (c < wire::kChannelCount)
        inputs[i] = wire::ScaleChannel(raw[c], record.channels[c], clips);
    }
    std::cout << filter.Step(inputs) << '\n';
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (args.size() == 2 && args[0] == "record") return Record(args[1]);
  if (args.size() == 3 && args[0] == "replay") return Replay(args[1], args[2]);
  return Fail("usage: vibid_qemu_dob_reference record OUT.bin | replay RECORD.bin FRAMES.txt");
}
