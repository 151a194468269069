// The CLI's bad-input matrix: every reader of outside data (recording CSV, FRF CSV, UFF58, model,
// design, sensors and rig JSON) and option values, each given a missing, empty, truncated,
// non-UTF-8, binary, huge or wrong file. Every row must end with exit code 1, one line on stderr
// naming the file (or option) and the problem, and no output file (nor a temporary one) left.
// Each reader also has a positive control with good files, so a row cannot pass by the command
// failing for another reason.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "run_cli.hpp"

namespace vibid::testing {
namespace {

namespace fs = std::filesystem;

void WriteBytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out << bytes;
}

// A 1-DOF rig (m = 1 kg, k = 4e4 N/m, c = 20 N s/m) driven by a deterministic random force at
// 1 kHz, integrated exactly enough for a well-formed recording: only the file's form matters here.
std::string GoodRecording() {
  std::ostringstream out;
  out << "t_s,force_n,x_m,acc_m_s2\n";
  double x = 0.0, v = 0.0;
  std::uint32_t lcg = 12345;
  const double dt = 1e-3;
  for (int i = 0; i < 8192; ++i) {
    lcg = lcg * 1664525u + 1013904223u;
    const double f = (static_cast<double>(lcg >> 8) / 16777216.0 - 0.5) * 10.0;
    const double a = f - 20.0 * v - 4e4 * x;
    char row[96];
    std::snprintf(row, sizeof(row), "%.3f,%.9g,%.9g,%.9g\n", i * dt, f, x, a);
    out << row;
    for (int k = 0; k < 10; ++k) {  // semi-implicit Euler at dt/10
      const double ak = f - 20.0 * v - 4e4 * x;
      v += ak * dt / 10.0;
      x += v * dt / 10.0;
    }
  }
  return out.str();
}

constexpr const char* kModel =
    "{\n  \"topology\": \"chain\",\n  \"masses\": [2.0, 1.5],\n  \"springs\": [4000.0, 3000.0],\n"
    "  \"dampers\": [6.0, 4.5]\n}\n";

constexpr const char* kSensors =
    "{\"format\": \"vibid-sensors\", \"version\": 1, \"channels\": {\n"
    "  \"force1\": {\"unit\": \"N\", \"counts_per_unit\": 4.096, \"offset_counts\": 2048, "
    "\"full_scale\": 500, \"dof\": 2},\n"
    "  \"x2\": {\"unit\": \"m\", \"counts_per_unit\": 100000, \"offset_counts\": 0, "
    "\"full_scale\": 0.05, \"dof\": 2}}}\n";

// The emulator's rig file: the true physics, sensors and converters of a simulated 1-DOF cart.
constexpr const char* kRig =
    "{\"topology\": \"chain\", \"masses_kg\": [0.5848], \"effective_mass_loss\": [0.0],\n"
    " \"springs_n_per_m\": [712.6], \"dampers_ns_per_m\": [0.73], \"coulomb_n\": [0.01],\n"
    " \"load_cells\": [{\"range_n\": 100.0, \"noise_n\": 0.02, \"adc_bits\": 12},\n"
    "                {\"range_n\": 20.0, \"noise_n\": 0.005, \"adc_bits\": 12}],\n"
    " \"accelerometers\": [{\"range_m_s2\": 100.0, \"noise_m_s2\": 0.02, \"adc_bits\": 12},\n"
    "                    {\"range_m_s2\": 100.0, \"noise_m_s2\": 0.02, \"adc_bits\": 12}],\n"
    " \"encoder_counts_per_m\": 56000.0, \"max_sample_rate_hz\": 10000.0}\n";

// How the bad file of a row is made.
enum class Make { kMissing, kContent, kSparse, kDirectory };

struct Row {
  std::string name;
  std::string file;  // name of the file under test in the row's directory
  Make make = Make::kContent;
  std::string content;             // kContent: the bytes; kSparse: ignored
  std::uint64_t sparse_bytes = 0;  // kSparse: the file's size (no disk blocks)
  std::vector<std::string>
      args;  // {IN}: the file under test, {OUT}: the output, {DIR}: the directory
  std::vector<std::string> expect;  // fragments of the one-line message
  bool emulator = false;            // run vibid-emu instead of vibid
};

class BadInput : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(MakeTempDir("bad-input"));
    const std::string& d = *dir_;
    WriteBytes(d + "/rec.csv", GoodRecording());
    WriteBytes(d + "/model.json", kModel);
    WriteBytes(d + "/sensors.json", kSensors);
    // The positive controls double as the makers of the derived good files.
    const CliResult frf =
        RunVibid({"frf-estimate", d + "/rec.csv", "--force", "force_n", "--response", "acc_m_s2",
                  "--welch", "--segment", "1024", "-o", d + "/frf.csv"});
    ASSERT_EQ(frf.exit_code, 0) << frf.err;
    const CliResult uff =
        RunVibid({"frf-estimate", d + "/rec.csv", "--force", "force_n", "--response", "acc_m_s2",
                  "--welch", "--segment", "1024", "-o", d + "/frf.uff"});
    ASSERT_EQ(uff.exit_code, 0) << uff.err;
    // The 2-DOF model's SISO observer from the force on mass 1 to the displacement of mass 1.
    const CliResult design =
        RunVibid({"dob", "design", d + "/model.json", "--fs-hz", "1000", "--input-dof", "1",
                  "--output-dof", "1", "--sensor", "disp", "-o", d + "/design.json"});
    ASSERT_EQ(design.exit_code, 0) << design.err;
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(*dir_, ec);
    delete dir_;
  }

  // Runs one row in a directory of its own (so "nothing left behind" is checkable) and checks the
  // exit code, the single line and its fragments, and that the directory holds only the input.
  static void Check(const Row& row) {
    SCOPED_TRACE(row.name);
    const std::string d = *dir_ + "/" + row.name;
    fs::create_directories(d);
    const std::string in = d + "/" + row.file;
    switch (row.make) {
      case Make::kMissing: break;
      case Make::kContent: WriteBytes(in, row.content); break;
      case Make::kDirectory: fs::create_directories(in); break;
      case Make::kSparse:
        WriteBytes(in, "");
        ASSERT_EQ(::truncate(in.c_str(), static_cast<off_t>(row.sparse_bytes)), 0);
        break;
    }
    const std::string out = d + "/out" + (row.file.ends_with(".uff") ? ".json" : ".csv");
    std::vector<std::string> args;
    for (std::string a : row.args) {
      for (const auto& [key, value] :
           {std::pair<std::string, std::string>{"{IN}", in}, {"{OUT}", out}, {"{DIR}", *dir_}}) {
        for (auto at = a.find(key); at != std::string::npos; at = a.find(key))
          a.replace(at, key.size(), value);
      }
      args.push_back(a);
    }
    const CliResult r = row.emulator ? RunProgram(VIBID_EMU_PATH, args) : RunVibid(args);
    std::cout << "  " << row.name << " -> " << r.exit_code << " "
              << r.err;  // the matrix, as users see it
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    for (const std::string& e : row.expect)
      EXPECT_NE(r.err.find(e), std::string::npos) << "want '" << e << "' in: " << r.err;
    // Only the input itself may be in the row's directory: no output, no temporary file.
    for (const auto& entry : fs::directory_iterator(d)) {
      EXPECT_EQ(entry.path().filename().string(), row.file) << "left behind: " << entry.path();
    }
    std::error_code ec;
    fs::remove_all(d, ec);  // the sparse files take no blocks, but their size is not kept around
  }

  static std::string* dir_;
};

std::string* BadInput::dir_ = nullptr;

std::string Cut(const std::string& text, double fraction) {
  return text.substr(0, static_cast<std::size_t>(static_cast<double>(text.size()) * fraction));
}

// Replaces the first occurrence of `what` in `text` (the row's mistake in an otherwise good file).
std::string With(std::string text, const std::string& what, const std::string& by) {
  const auto at = text.find(what);
  if (at != std::string::npos) text.replace(at, what.size(), by);
  return text;
}

// The line `line` (from 1) with its first 'E' (an exponent) replaced by the byte 0xFF.
std::string CorruptLine(std::string text, int line) {
  std::size_t at = 0;
  for (int i = 1; i < line; ++i) at = text.find('\n', at) + 1;
  text[text.find('E', at)] = '\xFF';
  return text;
}

TEST_F(BadInput, PositiveControls) {
  const std::string& d = *dir_;
  const CliResult sim = RunVibid({"simulate", d + "/model.json", "--dt-s", "0.001", "--t-end-s",
                                  "0.01", "--force", "step:dof=1,amp=1", "-o", d + "/sim.csv"});
  EXPECT_EQ(sim.exit_code, 0) << sim.err;
  for (const char* frf : {"/frf.csv", "/frf.uff"}) {
    const CliResult m =
        RunVibid({"modes", d + frf, "--method", "peaks", "--max-modes", "1", "--json"});
    EXPECT_EQ(m.exit_code, 0) << m.err;
  }
  const CliResult run = RunVibid({"dob", "run", d + "/rec.csv", "--design", d + "/design.json",
                                  "--force", "force_n", "--response", "x_m", "-o", d + "/dob.csv"});
  EXPECT_EQ(run.exit_code, 0) << run.err;
  // With good files, cal upload gets as far as the device (none listens there): exit 4, not 1.
  const CliResult cal =
      RunVibid({"--device", "usbip://127.0.0.1:9", "cal", "upload", d + "/model.json", "--design",
                d + "/design.json", "--sensors", d + "/sensors.json"});
  EXPECT_EQ(cal.exit_code, 4) << cal.err;
  WriteBytes(d + "/rig.json", kRig);
  const CliResult emu = RunProgram(VIBID_EMU_PATH, {"--rig", d + "/rig.json", "--print-truth"});
  EXPECT_EQ(emu.exit_code, 0) << emu.err;
}

TEST_F(BadInput, RecordingCsv) {
  const std::vector<std::string> frf = {"frf-estimate", "{IN}",     "--force", "force_n",
                                        "--response",   "acc_m_s2", "--welch", "--segment",
                                        "1024",         "-o",       "{OUT}"};
  const std::string good = GoodRecording();
  std::string nan = good;
  nan.replace(nan.find("\n0.100,") + 7, 0, "nan");  // "nan<number>": a cell that is not a number
  std::string nan_cell = good;                      // the force of row 202 (t = 0.200 s) made NaN
  const auto row202 = nan_cell.find("\n0.200,") + 7;
  nan_cell.replace(row202, nan_cell.find(',', row202) - row202, "nan");
  const std::string non_uniform = With(good, "\n0.300,", "\n0.3004,");
  const std::vector<Row> rows = {
      {"missing", "rec.csv", Make::kMissing, "", 0, frf, {"rec.csv", "cannot open"}},
      {"empty", "rec.csv", Make::kContent, "", 0, frf, {"rec.csv", "empty file"}},
      {"header_only",
       "rec.csv",
       Make::kContent,
       "t_s,force_n,x_m,acc_m_s2\n",
       0,
       frf,
       {"rec.csv", "too short"}},
      {"truncated",
       "rec.csv",
       Make::kContent,
       Cut(good, 0.5) + "\n",
       0,
       frf,
       {"rec.csv:", "expected 4 cells"}},
      {"not_utf8",
       "rec.csv",
       Make::kContent,
       With(good, "force_n",
            "for\xFF"
            "ce_n"),
       0,
       frf,
       {"rec.csv:1:8:", "not UTF-8"}},
      {"utf16",
       "rec.csv",
       Make::kContent,
       "\xFF\xFEt\0_\0s\0" + good,
       0,
       frf,
       {"rec.csv", "UTF-16"}},
      {"binary",
       "rec.csv",
       Make::kContent,
       std::string(4096, '\0'),
       0,
       frf,
       {"rec.csv:1:1:", "byte 0x00"}},
      {"huge",
       "rec.csv",
       Make::kSparse,
       "",
       std::uint64_t{5} << 30,
       frf,
       {"rec.csv", "too large", "5.00 GiB"}},
      {"directory", "rec.csv", Make::kDirectory, "", 0, frf, {"rec.csv", "directory"}},
      {"bad_byte_in_cell",
       "rec.csv",
       Make::kContent,
       With(good, "\n0.010,", "\n0.010,\xFF"),
       0,
       frf,
       {"rec.csv:12:", "'\\xFF", "is not a number"}},
      {"not_a_number", "rec.csv", Make::kContent, nan, 0, frf, {"rec.csv:102:", "is not a number"}},
      {"nan", "rec.csv", Make::kContent, nan_cell, 0, frf, {"rec.csv:202:", "non-finite"}},
      {"non_uniform_time",
       "rec.csv",
       Make::kContent,
       non_uniform,
       0,
       frf,
       {"rec.csv:302:", "non-uniform sampling"}},
      {"wrong_column",
       "rec.csv",
       Make::kContent,
       good,
       0,
       {"frf-estimate", "{IN}", "--force", "force_n", "--response", "acc2_m_s2", "--welch", "-o",
        "{OUT}"},
       {"rec.csv", "no column 'acc2_m_s2'"}},
      {"unknown_unit",
       "rec.csv",
       Make::kContent,
       good,
       0,
       {"frf-estimate", "{IN}", "--force", "force_n:furlong", "--response", "acc_m_s2", "--welch",
        "-o", "{OUT}"},
       {"column 'force_n:furlong'", "unknown unit 'furlong'"}},
  };
  for (const Row& row : rows) Check(row);
}

TEST_F(BadInput, ModelJson) {
  const std::vector<std::string> sim = {"simulate",  "{IN}", "--dt-s",  "0.001",
                                        "--t-end-s", "0.01", "--force", "step:dof=1,amp=1",
                                        "-o",        "{OUT}"};
  const std::string good = kModel;
  const std::vector<Row> rows = {
      {"model_missing", "model.json", Make::kMissing, "", 0, sim, {"model.json", "cannot open"}},
      {"model_empty", "model.json", Make::kContent, "", 0, sim, {"model.json", "empty file"}},
      {"model_truncated",
       "model.json",
       Make::kContent,
       Cut(good, 0.6),
       0,
       sim,
       {"model.json:", "truncated"}},
      {"model_not_utf8",
       "model.json",
       Make::kContent,
       With(good, "chain", "ch\xC3(in"),
       0,
       sim,
       {"model.json:2:", "not UTF-8", "0xC3"}},
      {"model_huge",
       "model.json",
       Make::kSparse,
       "",
       std::uint64_t{100} << 20,
       sim,
       {"model.json", "too large"}},
      {"model_nan",
       "model.json",
       Make::kContent,
       With(good, "2.0,", "NaN,"),
       0,
       sim,
       {"model.json:3:", "malformed JSON"}},
      {"model_wrong_keys",
       "model.json",
       Make::kContent,
       With(good, "\"masses\"", "\"mass\""),
       0,
       sim,
       {"model.json", "masses"}},
      {"model_misspelt_optional_key",
       "model.json",
       Make::kContent,
       With(kModel, "\"dampers\"", "\"damper\""),
       0,
       sim,
       {"unknown key 'damper' in model file", "model.json (did you mean 'dampers'?)"}},
      {"model_negative_mass",
       "model.json",
       Make::kContent,
       With(good, "2.0,", "-2.0,"),
       0,
       sim,
       {"model.json", "mass"}},
      {"model_not_an_object",
       "model.json",
       Make::kContent,
       "[1, 2, 3]\n",
       0,
       sim,
       {"model.json", "JSON object"}},
  };
  for (const Row& row : rows) Check(row);
}

TEST_F(BadInput, FrfFiles) {
  const std::vector<std::string> modes = {"modes", "{IN}",   "--method", "peaks", "--max-modes",
                                          "1",     "--json", "-o",       "{OUT}"};
  const std::string csv = ReadFileBytes(*dir_ + "/frf.csv");
  const std::string uff = ReadFileBytes(*dir_ + "/frf.uff");
  ASSERT_FALSE(csv.empty());
  ASSERT_FALSE(uff.empty());
  const std::vector<Row> rows = {
      {"frf_no_im",
       "frf.csv",
       Make::kContent,
       With(csv, "acc_m_s2_im", "acc_m_s2_imag"),
       0,
       modes,
       {"frf.csv", "has no acc_m_s2_im"}},
      {"frf_truncated", "frf.csv", Make::kContent, Cut(csv, 0.5), 0, modes, {"frf.csv:", "cells"}},
      {"frf_not_utf8",
       "frf.csv",
       Make::kContent,
       With(csv, "acc_m_s2_re", "acc_m_s2_r\xE9"),
       0,
       modes,
       {"frf.csv:1:", "not UTF-8"}},
      {"frf_empty", "frf.csv", Make::kContent, "", 0, modes, {"frf.csv", "empty file"}},
      {"uff_truncated", "frf.uff", Make::kContent, Cut(uff, 0.5), 0, modes, {"frf.uff"}},
      {"uff_garbage_number",
       "frf.uff",
       Make::kContent,
       CorruptLine(uff, 14),
       0,
       modes,
       {"frf.uff", "\\xFF", "not a finite number"}},
      {"uff_empty", "frf.uff", Make::kContent, "", 0, modes, {"frf.uff"}},
      {"uff_huge",
       "frf.uff",
       Make::kSparse,
       "",
       std::uint64_t{2} << 30,
       modes,
       {"frf.uff", "too large"}},
  };
  for (const Row& row : rows) Check(row);
}

TEST_F(BadInput, DesignSensorsAndRigJson) {
  const std::string design = ReadFileBytes(*dir_ + "/design.json");
  ASSERT_FALSE(design.empty());
  const std::vector<std::string> run = {"dob",  "run",     "{DIR}/rec.csv", "--design",
                                        "{IN}", "--force", "force_n",       "--response",
                                        "x_m",  "-o",      "{OUT}"};
  const std::vector<std::string> cal = {
      "--device", "usbip://127.0.0.1:9", "cal",       "upload", "{DIR}/model.json",
      "--design", "{DIR}/design.json",   "--sensors", "{IN}"};
  const std::vector<std::string> emu = {"--rig", "{IN}", "--print-truth"};
  const std::string sensors = kSensors;
  const std::vector<Row> rows = {
      {"design_truncated",
       "design.json",
       Make::kContent,
       Cut(design, 0.5),
       0,
       run,
       {"design.json:", "truncated"}},
      {"design_is_a_model",
       "design.json",
       Make::kContent,
       kModel,
       0,
       run,
       {"design.json", "not a vibid DOB design"}},
      {"design_not_utf8",
       "design.json",
       Make::kContent,
       "\xFF\xFE{}",
       0,
       run,
       {"design.json", "UTF-16"}},
      {"sensors_truncated",
       "sensors.json",
       Make::kContent,
       Cut(sensors, 0.7),
       0,
       cal,
       {"sensors.json:", "truncated"}},
      {"sensors_unknown_unit",
       "sensors.json",
       Make::kContent,
       With(sensors, "\"unit\": \"m\"", "\"unit\": \"furlong\""),
       0,
       cal,
       {"sensors.json", "furlong"}},
      {"sensors_empty", "sensors.json", Make::kContent, "", 0, cal, {"sensors.json", "empty file"}},
      {"sensors_misspelt_key",
       "sensors.json",
       Make::kContent,
       With(sensors, "\"offset_counts\": 0", "\"offset_count\": 0"),
       0,
       cal,
       {"unknown key 'offset_count' in sensors file", "sensors.json channels.x2",
        "(did you mean 'offset_counts'?)"}},
      {"rig_truncated",
       "rig.json",
       Make::kContent,
       Cut(kRig, 0.5),
       0,
       emu,
       {"rig.json:", "truncated"},
       true},
      {"rig_negative_spring",
       "rig.json",
       Make::kContent,
       With(kRig, "712.6", "-712.6"),
       0,
       emu,
       {"rig.json", "springs_n_per_m"},
       true},
      {"rig_no_masses",
       "rig.json",
       Make::kContent,
       With(kRig, "masses_kg", "mass_kg"),
       0,
       emu,
       {"rig.json", "unknown key 'mass_kg' in rig file", "(did you mean 'masses_kg'?)"},
       true},
      {"rig_missing", "rig.json", Make::kMissing, "", 0, emu, {"rig.json", "cannot open"}, true},
  };
  for (const Row& row : rows) Check(row);
}

TEST_F(BadInput, OptionValues) {
  const std::vector<Row> rows = {
      {"tau_negative",
       "model.json",
       Make::kContent,
       kModel,
       0,
       {"dob", "design", "{IN}", "--tau-s", "-1", "-o", "{OUT}"},
       {"--tau-s", "-1"}},
      {"dt_not_a_number",
       "model.json",
       Make::kContent,
       kModel,
       0,
       {"simulate", "{IN}", "--dt-s", "abc", "--t-end-s", "1", "--force", "step:dof=1,amp=1", "-o",
        "{OUT}"},
       {"--dt-s", "abc"}},
      {"segment_longer_than_record",
       "rec.csv",
       Make::kContent,
       GoodRecording(),
       0,
       {"frf-estimate", "{IN}", "--force", "force_n", "--response", "acc_m_s2", "--welch",
        "--segment", "100000", "-o", "{OUT}"},
       {"rec.csv", "--segment of 100000"}},
      {"lowpass_order_out_of_range",
       "rec.csv",
       Make::kContent,
       GoodRecording(),
       0,
       {"dob", "run", "{IN}", "--design", "{DIR}/design.json", "--force", "force_n", "--response",
        "x_m", "--lowpass-order", "99", "-o", "{OUT}"},
       {"--lowpass-order", "99"}},
      {"force_dof_out_of_range",
       "model.json",
       Make::kContent,
       kModel,
       0,
       {"simulate", "{IN}", "--dt-s", "0.001", "--t-end-s", "0.01", "--force", "step:dof=7,amp=1",
        "-o", "{OUT}"},
       {"dof"}},
  };
  for (const Row& row : rows) Check(row);
}

}  // namespace
}  // namespace vibid::testing
