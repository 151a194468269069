// The wire's CRC-32 is the shared one (vibid/shared/crc32.hpp), named in this namespace for the
// codecs.
#pragma once

#include "vibid/shared/crc32.hpp"

namespace vibid::wire {

using vibid::ComputeCrc32;
using vibid::Crc32;

}  // namespace vibid::wire
