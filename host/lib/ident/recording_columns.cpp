#include "vibid/ident/recording_columns.hpp"

namespace vibid::ident {

std::string ForceColumn() { return "force1_n"; }

std::string AccelerationColumn(std::size_t position) {
  return "acc" + std::to_string(position) + "_m_s2";
}

std::string AccelerationColumns(std::size_t masses) {
  std::string out;
  for (std::size_t p = 1; p <= masses; ++p) out += (p > 1 ? "," : "") + AccelerationColumn(p);
  return out;
}

}  // namespace vibid::ident
