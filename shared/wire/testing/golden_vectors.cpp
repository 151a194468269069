#include "golden_vectors.hpp"

#include "wire_vectors_data.hpp"

namespace vibid::wire::testing {
namespace {

// The text after "name " on the line that starts with it, up to the end of the line.
std::string_view FindValue(std::string_view name) {
  std::string_view text(kWireVectorsText);
  while (!text.empty()) {
    const std::size_t end = text.find('\n');
    const std::string_view line = text.substr(0, end);
    if (line.size() > name.size() && line.substr(0, name.size()) == name &&
        line[name.size()] == ' ') {
      return line.substr(name.size() + 1);
    }
    if (end == std::string_view::npos) break;
    text.remove_prefix(end + 1);
  }
  return {};
}

int HexDigit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

}  // namespace

std::size_t GoldenVector(std::string_view name, std::span<std::uint8_t> out) {
  const std::string_view hex = FindValue(name);
  if (hex.empty() || hex.size() % 2 != 0 || hex.size() / 2 > out.size()) return 0;
  for (std::size_t i = 0; i < hex.size() / 2; ++i) {
    const int hi = HexDigit(hex[2 * i]);
    const int lo = HexDigit(hex[2 * i + 1]);
    if (hi < 0 || lo < 0) return 0;
    out[i] = static_cast<std::uint8_t>(hi * 16 + lo);
  }
  return hex.size() / 2;
}

Report GoldenReport(std::string_view name) {
  Report r{};
  if (GoldenVector(name, r) != kReportBytes) r.fill(0);
  return r;
}

long GoldenConstant(std::string_view name) {
  const std::string_view digits = FindValue(name);
  if (digits.empty()) return -1;
  long v = 0;
  for (const char c : digits) {
    if (c < '0' || c > '9') return -1;
    v = v * 10 + (c - '0');
  }
  return v;
}

}  // namespace vibid::wire::testing
