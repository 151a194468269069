#include "vibid/ident/recording_facts.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "vibid/common/atomic_file.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/json_file.hpp"
#include "vibid/common/json_keys.hpp"

namespace vibid::ident {
namespace {

constexpr std::string_view kFormat = "vibid-recording";
using Json = nlohmann::ordered_json;

std::string Hex32(std::uint32_t v) {
  char b[16];
  std::snprintf(b, sizeof b, "0x%08X", static_cast<unsigned>(v));
  return b;
}

// Reads values of one object, each check naming the sidecar and the key's path.
class Reader {
 public:
  Reader(const nlohmann::json& object, std::string where) : j_(object), where_(std::move(where)) {}

  bool Has(const char* key) const { return j_.contains(key); }

  double Number(const char* key, bool finite_positive = false) const {
    const nlohmann::json& v = j_.at(key);
    Require(v.is_number() && std::isfinite(v.get<double>()) &&
                (!finite_positive || v.get<double>() > 0.0),
            where_ + " \"" + key + "\" must be a " + (finite_positive ? "number > 0" : "number") +
                ", not " + v.dump());
    return v.get<double>();
  }

  std::uint64_t Count(const char* key) const {
    const nlohmann::json& v = j_.at(key);
    Require(v.is_number_unsigned() || (v.is_number_integer() && v.get<std::int64_t>() >= 0),
            where_ + " \"" + key + "\" must be a whole number >= 0, not " + v.dump());
    return v.get<std::uint64_t>();
  }

  std::string Text(const char* key) const {
    const nlohmann::json& v = j_.at(key);
    Require(v.is_string(), where_ + " \"" + key + "\" must be a string, not " + v.dump());
    return v.get<std::string>();
  }

  std::uint32_t Hex(const char* key) const {
    const std::string s = Text(key);
    unsigned long v = 0;
    char* end = nullptr;
    if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X'))
      v = std::strtoul(s.c_str() + 2, &end, 16);
    Require(
        end != nullptr && *end == '\0' && s.size() <= 10 && s.size() > 2,
        where_ + " \"" + key + "\" must be a 32-bit hex number \"0x1234ABCD\", not \"" + s + "\"");
    return static_cast<std::uint32_t>(v);
  }

  std::pair<double, double> Range(const char* key) const {
    const nlohmann::json& v = j_.at(key);
    const bool ok = v.is_array() && v.size() == 2 && v[0].is_number() && v[1].is_number() &&
                    std::isfinite(v[0].get<double>()) && std::isfinite(v[1].get<double>()) &&
                    v[0].get<double>() < v[1].get<double>();
    Require(ok, where_ + " \"" + key + "\" must be [low, high] with low < high, not " + v.dump());
    return {v[0].get<double>(), v[1].get<double>()};
  }

 private:
  const nlohmann::json& j_;
  std::string where_;
};

Json ChannelJson(const ChannelFacts& c, const RecordingFacts& f) {
  Json j;
  j["name"] = c.name;
  if (!c.unit_str.empty()) j["unit_str"] = c.unit_str;
  // SEP005 states the rate and the start per channel.
  if (f.fs) j["fs"] = *f.fs;
  if (!f.start_timestamp.empty()) j["start_timestamp"] = f.start_timestamp;
  if (c.counts_per_unit) j["counts_per_unit"] = *c.counts_per_unit;
  if (c.offset_counts) j["offset_counts"] = *c.offset_counts;
  if (c.full_scale) j["full_scale"] = *c.full_scale;
  if (c.code_range) j["code_range"] = {c.code_range->first, c.code_range->second};
  if (c.rails) j["rails"] = {c.rails->first, c.rails->second};
  if (c.sample_instant_us) j["sample_instant_us"] = *c.sample_instant_us;
  if (c.clipped_samples) j["clipped_samples"] = *c.clipped_samples;
  return j;
}

ChannelFacts ParseChannel(const nlohmann::json& j, const RecordingFacts& f,
                          const std::string& where) {
  Require(j.is_object(), where + " must be an object {\"name\": COLUMN, ...}");
  RequireKnownKeys(j,
                   {"name", "unit_str", "fs", "start_timestamp", "counts_per_unit", "offset_counts",
                    "full_scale", "code_range", "rails", "sample_instant_us", "clipped_samples"},
                   where);
  const Reader r(j, where);
  Require(r.Has("name"), where + " has no \"name\"");
  ChannelFacts c;
  c.name = r.Text("name");
  Require(std::find(f.columns.begin(), f.columns.end(), c.name) != f.columns.end(),
          where + " names '" + c.name + "', not a column of the recording");
  if (r.Has("unit_str")) c.unit_str = r.Text("unit_str");
  if (r.Has("fs")) {
    const double fs = r.Number("fs", true);
    Require(!f.fs || *f.fs == fs, where + " \"fs\" " + std::to_string(fs) +
                                      " differs from the recording's " + std::to_string(*f.fs));
  }
  if (r.Has("start_timestamp")) (void)r.Text("start_timestamp");
  if (r.Has("counts_per_unit")) c.counts_per_unit = r.Number("counts_per_unit", true);
  if (r.Has("offset_counts")) c.offset_counts = r.Number("offset_counts");
  if (r.Has("full_scale")) c.full_scale = r.Number("full_scale", true);
  if (r.Has("code_range")) c.code_range = r.Range("code_range");
  if (r.Has("rails")) c.rails = r.Range("rails");
  if (r.Has("sample_instant_us")) {
    const double us = r.Number("sample_instant_us");
    Require(us >= 0.0, where + " \"sample_instant_us\" must be >= 0");
    c.sample_instant_us = us;
  }
  if (r.Has("clipped_samples")) c.clipped_samples = r.Count("clipped_samples");
  return c;
}

}  // namespace

const ChannelFacts* RecordingFacts::Channel(std::string_view name) const {
  for (const ChannelFacts& c : channels) {
    if (c.name == name) return &c;
  }
  return nullptr;
}

std::string FormatRecordingFacts(const RecordingFacts& f) {
  Json j;
  j["format"] = std::string(kFormat);
  j["version"] = 2;
  j["columns"] = f.columns;
  if (f.fs) j["fs"] = *f.fs;
  if (!f.start_timestamp.empty()) j["start_timestamp"] = f.start_timestamp;
  if (f.board) {
    const BoardFacts& b = *f.board;
    j["board"] = {{"board", b.board},
                  {"serial", b.serial},
                  {"firmware", b.firmware},
                  {"protocol", b.protocol},
                  {"build_id", Hex32(b.build_id)},
                  {"adc_bits", b.adc_bits}};
  }
  if (f.calibration) {
    j["calibration"] = {{"label", f.calibration->label},
                        {"crc32", Hex32(f.calibration->crc32)},
                        {"created_unix_s", f.calibration->created_unix_s}};
  }
  if (f.acquisition) {
    const AcquisitionFacts& a = *f.acquisition;
    Json aj;
    aj["sample_rate_hz"] = a.sample_rate_hz;
    aj["decimation"] = a.decimation;
    if (a.seconds > 0.0) aj["seconds"] = a.seconds;
    aj["trigger"] = a.trigger;
    aj["pretrigger_s"] = a.pretrigger_s;
    aj["records"] = a.records;
    aj["dropped_records"] = a.dropped_records;
    aj["overrun_ticks"] = a.overrun_ticks;
    if (!a.scenario.empty()) {
      aj["scenario"] = a.scenario;
      aj["scenario_params"] = a.scenario_params;
    }
    if (a.emulator_seed) aj["emulator_seed"] = *a.emulator_seed;
    j["acquisition"] = aj;
  }
  Json channels = Json::array();
  for (const ChannelFacts& c : f.channels) {
    Require(std::find(f.columns.begin(), f.columns.end(), c.name) != f.columns.end(),
            "recording facts: '" + c.name + "' is not a column of the recording");
    channels.push_back(ChannelJson(c, f));
  }
  j["channels"] = channels;
  // Numbers in shortest round-trip form (nlohmann's): 2.667 reads back as the same double.
  return j.dump(2) + "\n";
}

RecordingFacts ParseRecordingFacts(std::string_view json,
                                   const std::vector<std::string>& csv_columns,
                                   const std::string& source) {
  const nlohmann::json j = ParseJsonText(json, source);
  Require(j.is_object() && j.value("format", nlohmann::json()) == std::string(kFormat),
          source + ": not a vibid-recording sidecar (\"format\": \"vibid-recording\")");
  const nlohmann::json version = j.value("version", nlohmann::json());
  Require(version == 1 || version == 2,
          source + ": version " + version.dump() + " is not one this vibid reads (1 or 2)");
  RecordingFacts f;
  f.version = version.get<int>();
  if (f.version == 1) {
    RequireKnownKeys(j, {"format", "version", "columns", "sample_instants_us"}, source);
  } else {
    RequireKnownKeys(j,
                     {"format", "version", "columns", "fs", "start_timestamp", "board",
                      "calibration", "acquisition", "channels"},
                     source);
  }
  const nlohmann::json& columns = j.contains("columns") ? j.at("columns") : nlohmann::json();
  std::vector<std::string> names;
  bool all_strings = columns.is_array();
  if (all_strings) {
    for (const nlohmann::json& c : columns) {
      all_strings = all_strings && c.is_string();
      if (c.is_string()) names.push_back(c.get<std::string>());
    }
  }
  Require(all_strings, source + ": \"columns\" must be a list of names");
  std::string header;
  for (const std::string& n : csv_columns) header += (header.empty() ? "" : ",") + n;
  Require(names == csv_columns,
          source + ": describes columns " + columns.dump() + ", the recording's are " + header +
              ": it belongs to another recording; remove it (the recording is then read without "
              "its facts) or put the recording's own beside it");
  f.columns = names;
  if (f.version == 1) {
    const nlohmann::json& list =
        j.contains("sample_instants_us") ? j.at("sample_instants_us") : nlohmann::json();
    Require(list.is_object(), source + ": \"sample_instants_us\" must be an object {column: us}");
    for (const auto& item : list.items()) {
      const std::string& name = item.key();
      Require(std::find(csv_columns.begin(), csv_columns.end(), name) != csv_columns.end(),
              source + ": sample_instants_us names '" + name + "', not a column of the recording");
      const nlohmann::json& v = item.value();
      Require(v.is_number() && std::isfinite(v.get<double>()) && v.get<double>() >= 0.0,
              source + ": sample_instants_us of '" + name + "' is not a number >= 0: " + v.dump());
      ChannelFacts c;
      c.name = name;
      c.sample_instant_us = v.get<double>();
      f.channels.push_back(c);
    }
    return f;
  }
  const Reader top(j, source + ":");
  if (top.Has("fs")) f.fs = top.Number("fs", true);
  if (top.Has("start_timestamp")) f.start_timestamp = top.Text("start_timestamp");
  if (top.Has("board")) {
    const nlohmann::json& b = j.at("board");
    const std::string where = source + ": \"board\"";
    Require(b.is_object(), where + " must be an object");
    RequireKnownKeys(b, {"board", "serial", "firmware", "protocol", "build_id", "adc_bits"}, where);
    const Reader r(b, where);
    BoardFacts out;
    if (r.Has("board")) out.board = r.Text("board");
    if (r.Has("serial")) out.serial = r.Text("serial");
    if (r.Has("firmware")) out.firmware = r.Text("firmware");
    if (r.Has("protocol")) out.protocol = r.Text("protocol");
    if (r.Has("build_id")) out.build_id = r.Hex("build_id");
    if (r.Has("adc_bits")) out.adc_bits = static_cast<std::uint32_t>(r.Count("adc_bits"));
    f.board = out;
  }
  if (top.Has("calibration")) {
    const nlohmann::json& c = j.at("calibration");
    const std::string where = source + ": \"calibration\"";
    Require(c.is_object(), where + " must be an object");
    RequireKnownKeys(c, {"label", "crc32", "created_unix_s"}, where);
    const Reader r(c, where);
    CalibrationFacts out;
    if (r.Has("label")) out.label = r.Text("label");
    if (r.Has("crc32")) out.crc32 = r.Hex("crc32");
    if (r.Has("created_unix_s"))
      out.created_unix_s = static_cast<std::int64_t>(r.Count("created_unix_s"));
    f.calibration = out;
  }
  if (top.Has("acquisition")) {
    const nlohmann::json& a = j.at("acquisition");
    const std::string where = source + ": \"acquisition\"";
    Require(a.is_object(), where + " must be an object");
    RequireKnownKeys(
        a,
        {"sample_rate_hz", "decimation", "seconds", "trigger", "pretrigger_s", "records",
         "dropped_records", "overrun_ticks", "scenario", "scenario_params", "emulator_seed"},
        where);
    const Reader r(a, where);
    AcquisitionFacts out;
    if (r.Has("sample_rate_hz")) out.sample_rate_hz = r.Number("sample_rate_hz", true);
    if (r.Has("decimation")) out.decimation = static_cast<std::uint32_t>(r.Count("decimation"));
    if (r.Has("seconds")) out.seconds = r.Number("seconds", true);
    if (r.Has("trigger")) out.trigger = r.Text("trigger");
    if (r.Has("pretrigger_s")) out.pretrigger_s = r.Number("pretrigger_s");
    if (r.Has("records")) out.records = r.Count("records");
    if (r.Has("dropped_records")) out.dropped_records = r.Count("dropped_records");
    if (r.Has("overrun_ticks")) out.overrun_ticks = r.Count("overrun_ticks");
    if (r.Has("scenario")) out.scenario = r.Text("scenario");
    if (r.Has("scenario_params")) {
      const nlohmann::json& p = a.at("scenario_params");
      Require(p.is_array(), where + " \"scenario_params\" must be a list of numbers");
      for (const nlohmann::json& v : p) {
        Require(v.is_number() && std::isfinite(v.get<double>()),
                where + " \"scenario_params\" must be a list of numbers, not " + p.dump());
        out.scenario_params.push_back(v.get<double>());
      }
    }
    if (r.Has("emulator_seed")) out.emulator_seed = r.Count("emulator_seed");
    f.acquisition = out;
  }
  if (j.contains("channels")) {
    const nlohmann::json& list = j.at("channels");
    Require(list.is_array(), source + ": \"channels\" must be a list of channel objects");
    for (std::size_t i = 0; i < list.size(); ++i) {
      ChannelFacts c =
          ParseChannel(list[i], f, source + ": \"channels\"[" + std::to_string(i) + "]");
      Require(f.Channel(c.name) == nullptr,
              source + ": \"channels\" describes '" + c.name + "' twice");
      f.channels.push_back(std::move(c));
    }
  }
  return f;
}

std::optional<RecordingFacts> ReadRecordingFacts(const std::string& csv_path) {
  const std::string sidecar = csv_path + ".json";
  if (!std::filesystem::exists(sidecar)) return std::nullopt;
  std::ifstream in(csv_path, std::ios::binary);
  Require(in.good(), "cannot open " + csv_path);
  std::string line;
  // Comment lines of recordings written before the sidecar come before the header row.
  while (in.peek() == '#' && std::getline(in, line)) {
  }
  std::string header_row;
  std::getline(in, header_row);
  if (!header_row.empty() && header_row.back() == '\r') header_row.pop_back();
  std::vector<std::string> columns;
  for (const std::string& c : SplitList(header_row)) {
    // Header cells are trimmed, as the CSV reader trims them.
    const std::size_t first = c.find_first_not_of(" \t");
    const std::size_t last = c.find_last_not_of(" \t");
    columns.push_back(first == std::string::npos ? std::string()
                                                 : c.substr(first, last - first + 1));
  }
  return ParseRecordingFacts(ReadFileText(sidecar), columns, sidecar);
}

void WriteRecordingFacts(const std::string& csv_path, const RecordingFacts& facts) {
  WriteFileAtomic(csv_path + ".json", FormatRecordingFacts(facts));
}

std::string UtcTimestampNow() {
  const auto now = std::chrono::system_clock::now();
  const std::time_t s = std::chrono::system_clock::to_time_t(now);
  const auto ms =
      std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()) % 1000;
  std::tm utc{};
  gmtime_r(&s, &utc);
  char b[96];
  std::snprintf(b, sizeof b, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", utc.tm_year + 1900,
                utc.tm_mon + 1, utc.tm_mday, utc.tm_hour, utc.tm_min, utc.tm_sec,
                static_cast<int>(ms.count()));
  return b;
}

}  // namespace vibid::ident
