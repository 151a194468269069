#include "vibid/ident/sample_instants.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <complex>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>

#include "vibid/common/error.hpp"

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
    out.instants_s.emplace_back(name, us * 1e-6);
    begin = end + 1;
  }
  return out;
}

}  // namespace

std::optional<double> SampleInstants::Of(std::string_view column) const {
  for (const auto& [name, t] : instants_s) {
    if (name == column) return t;
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

std::optional<SampleInstants> ReadSampleInstants(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  Require(in.good(), "cannot open " + path);
  // The header lines come first; the numbers after them are not needed.
  std::string head;
  std::string line;
  while (in.peek() == '#' && std::getline(in, line)) head += line + "\n";
  return ParseSampleInstants(head, path);
}

std::string FormatSampleInstantsLine(const std::vector<std::string>& columns,
                                     const std::vector<double>& instants_us) {
  std::string out = std::string(kLineTag) + " " + std::string(kKey);
  for (std::size_t i = 0; i < columns.size(); ++i) {
    // Shortest form that reads back to the same double.
    std::array<char, 32> number{};
    const auto r = std::to_chars(number.data(), number.data() + number.size(), instants_us[i]);
    out += (i == 0 ? "" : ",") + columns[i] + ":" + std::string(number.data(), r.ptr);
  }
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
