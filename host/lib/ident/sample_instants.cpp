#include "vibid/ident/sample_instants.hpp"

#include <algorithm>
#include <array>
#include <filesystem>
#include <charconv>
#include <cmath>
#include <complex>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>

#include <nlohmann/json.hpp>

#include "vibid/common/atomic_file.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/json_file.hpp"
#include "vibid/common/json_keys.hpp"
#include "vibid/ident/recording_facts.hpp"

namespace vibid::ident {
namespace {

constexpr std::string_view kLineTag = "# vibid-recording";
constexpr std::string_view kKey = "sample_instants_us=";

SampleInstants ParseList(std::string_view list, const std::string& source) {
  SampleInstants out;
  std::size_t begin = 0;
  while (begin <= list.size()) {
    const std::size_t end = std::min(list.find(',', begin), list.size());
    const std::string_view item = list.substr(begin, end - begin);
    const std::size_t colon = item.rfind(':');
    Require(colon != std::string_view::npos && colon > 0, source + ": sample_instants_us item '" +
                                                              std::string(item) +
                                                              "' is not COLUMN:MICROSECONDS");
    const std::string name(item.substr(0, colon));
    const std::string number(item.substr(colon + 1));
    std::size_t used = 0;
    double us = std::numeric_limits<double>::quiet_NaN();
    try {
      us = std::stod(number, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    Require(
        used == number.size() && !number.empty() && std::isfinite(us) && us >= 0.0,
        source + ": sample_instants_us of '" + name + "' is not a number >= 0: '" + number + "'");
    Require(!out.Of(name).has_value(), source + ": sample_instants_us names '" + name + "' twice");
    out.instants_us.emplace_back(name, us);
    begin = end + 1;
  }
  return out;
}

}  // namespace

std::optional<double> SampleInstants::Of(std::string_view column) const {
  for (const auto& [name, us] : instants_us) {
    if (name == column) return us * 1e-6;
  }
  return std::nullopt;
}

std::optional<SampleInstants> ParseSampleInstants(std::string_view text,
                                                  const std::string& source) {
  std::size_t pos = 0;
  while (pos < text.size() && text[pos] == '#') {
    const std::size_t eol = std::min(text.find('\n', pos), text.size());
    std::string_view line = text.substr(pos, eol - pos);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos = eol + 1;
    if (line.substr(0, kLineTag.size()) != kLineTag) continue;
    std::istringstream words{std::string(line.substr(kLineTag.size()))};
    std::string word;
    while (words >> word) {
      if (word.rfind(kKey, 0) == 0)
        return ParseList(std::string_view(word).substr(kKey.size()), source);
    }
  }
  return std::nullopt;
}

std::string RecordingSidecarPath(const std::string& csv_path) { return csv_path + ".json"; }

namespace {

SampleInstants InstantsOf(const RecordingFacts& facts) {
  SampleInstants out;
  for (const ChannelFacts& c : facts.channels) {
    if (c.sample_instant_us) out.instants_us.emplace_back(c.name, *c.sample_instant_us);
  }
  return out;
}

}  // namespace

std::string FormatRecordingSidecar(const std::vector<std::string>& csv_columns,
                                   const std::vector<InstantUs>& instants_us) {
  RecordingFacts facts;
  facts.columns = csv_columns;
  for (const auto& [name, us] : instants_us) {
    Require(std::find(csv_columns.begin(), csv_columns.end(), name) != csv_columns.end(),
            "sample instants: '" + name + "' is not a column of the recording");
    ChannelFacts c;
    c.name = name;
    c.sample_instant_us = us;
    facts.channels.push_back(c);
  }
  return FormatRecordingFacts(facts);
}

SampleInstants ParseRecordingSidecar(std::string_view json,
                                     const std::vector<std::string>& csv_columns,
                                     const std::string& source) {
  return InstantsOf(ParseRecordingFacts(json, csv_columns, source));
}

void WriteRecordingSidecar(const std::string& csv_path, const std::vector<std::string>& csv_columns,
                           const std::vector<InstantUs>& instants_us) {
  const std::string sidecar = RecordingSidecarPath(csv_path);
  if (instants_us.empty()) {
    std::error_code ec;
    std::filesystem::remove(sidecar, ec);
    Require(!ec, "cannot remove '" + sidecar + "' (left from an earlier recording at " + csv_path +
                     "): " + ec.message());
    return;
  }
  WriteFileAtomic(sidecar, FormatRecordingSidecar(csv_columns, instants_us));
}

std::optional<SampleInstants> ReadSampleInstants(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  Require(in.good(), "cannot open " + path);
  // The header lines come first; the numbers after them are not needed.
  std::string head;
  std::string line;
  while (in.peek() == '#' && std::getline(in, line)) head += line + "\n";
  const std::optional<RecordingFacts> facts = ReadRecordingFacts(path);
  if (!facts) return ParseSampleInstants(head, path);
  SampleInstants out = InstantsOf(*facts);
  // A sidecar that states no instant (a recording from a board of protocol 2.0) leaves the
  // channels at one instant, as no sidecar does.
  if (out.instants_us.empty()) return std::nullopt;
  return out;
}

void CompensateSampleInstants(Frf& frf, double force_instant_s,
                              const std::vector<double>& response_instants_s) {
  Require(response_instants_s.size() == frf.responses(),
          "sample instants: one per response is needed");
  for (std::size_t j = 0; j < frf.responses(); ++j) {
    const double dt_s = force_instant_s - response_instants_s[j];
    if (dt_s == 0.0) continue;
    for (Eigen::Index k = 0; k < frf.h.rows(); ++k) {
      const double omega = 2.0 * std::numbers::pi * frf.freq_hz(k);
      frf.h(k, static_cast<Eigen::Index>(j)) *= std::polar(1.0, omega * dt_s);
    }
  }
}

}  // namespace vibid::ident
