#include "vibid/fw/version.hpp"

#include "vibid_build_id.hpp"

namespace vibid::fw {

FirmwareVersion CurrentFirmwareVersion() {
  return FirmwareVersion{VIBID_FW_VERSION_MAJOR, VIBID_FW_VERSION_MINOR, VIBID_FW_VERSION_PATCH};
}

std::uint32_t BuildId() { return VIBID_FW_BUILD_ID; }

}  // namespace vibid::fw
