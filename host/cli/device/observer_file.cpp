#include "observer_file.hpp"

#include "vibid/common/error.hpp"
#include "vibid/common/json_file.hpp"

namespace vibid::cli {
namespace {

int HexDigit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

}  // namespace

fixed::FilterDescription LoadObserverDescription(const std::string& path) {
  const nlohmann::json j = ReadJsonFile(path);
  const auto fail = [&](const std::string& what) { throw InputError(path + ": " + what); };
  if (!j.is_object() || j.value("format", "") != "vibid-dob-design") fail("not a vibid DOB design file");
  std::string hex;
  try {
    hex = j.at("fixed").at("description_hex").get<std::string>();
  } catch (const nlohmann::json::exception&) {
    fail("missing fixed.description_hex");
  }
  std::array<std::uint8_t, fixed::kDescriptionBytes> bytes{};
  if (hex.size() != 2 * bytes.size()) fail("fixed.description_hex must hold " + std::to_string(bytes.size()) + " bytes");
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    const int hi = HexDigit(hex[2 * i]);
    const int lo = HexDigit(hex[2 * i + 1]);
    if (hi < 0 || lo < 0) fail("fixed.description_hex is not hexadecimal");
    bytes[i] = static_cast<std::uint8_t>(hi * 16 + lo);
  }
  fixed::FilterDescription d;
  const Status st = fixed::DecodeDescription(bytes, d);
  if (st != Status::kOk || fixed::ValidateDescription(d) != Status::kOk) {
    fail(std::string("the fixed-point observer is refused: ") + StatusName(st != Status::kOk ? st : fixed::ValidateDescription(d)));
  }
  return d;
}

}  // namespace vibid::cli
