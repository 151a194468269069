// The image-crc self-test check as every STM32F405 image answers it (the board and the QEMU
// image): the CRC computed over the image, passing when it equals the one the build wrote.
#pragma once

#include "image_crc.hpp"
#include "vibid/fw/port.hpp"

namespace vibid::fw::stm32 {

/// Unavailable without an image; a trailer that does not parse fails with the word where the
/// CRC should be (the image is not what the build wrote); else the computed CRC and whether it
/// equals the stored one.
inline SystemControl::SelfTestMeasurement ImageCrcMeasurement(const ImageView& image) {
  if (image.bytes == nullptr) return {};
  const ImageCrcResult r = CheckImageCrc(image);
  if (!r.trailer_valid) return {.available = true, .mantissa = r.stored, .exp10 = 0, .ok = false};
  return {.available = true, .mantissa = r.computed, .exp10 = 0, .ok = r.computed == r.stored};
}

}  // namespace vibid::fw::stm32
