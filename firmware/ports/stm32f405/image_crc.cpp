#include "image_crc.hpp"

#include <algorithm>
#include <span>

#include "system.hpp"
#include "vibid/shared/crc32.hpp"

namespace vibid::fw::stm32 {

namespace {

std::uint32_t LoadU32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}

// 16 KiB of CRC is about 0.1 ms at 168 MHz: far inside the 1 s watchdog, fed anyway so the
// check stays bounded whatever the image's size.
constexpr std::size_t kChunkBytes = 16 * 1024;

void Feed(Crc32& crc, const std::uint8_t* bytes, std::size_t n) {
  while (n > 0) {
    const std::size_t piece = std::min(n, kChunkBytes);
    crc.Update(std::span(bytes, piece));
    KickWatchdog();
    bytes += piece;
    n -= piece;
  }
}

}  // namespace

ImageCrcResult CheckImageCrc(const ImageView& image) {
  ImageCrcResult r;
  if (image.bytes == nullptr || image.size < kImageCrcTrailerBytes) return r;
  const std::uint8_t* t = image.bytes + image.size - kImageCrcTrailerBytes;
  const std::uint32_t magic = LoadU32(t);
  const std::uint32_t head_start = LoadU32(t + 4);
  const std::uint32_t head_end = LoadU32(t + 8);
  const std::uint32_t body_start = LoadU32(t + 12);
  const std::uint32_t body_end = LoadU32(t + 16);
  r.stored = LoadU32(t + 20);
  // The view's end in 64 bits: an address plus a size may pass 2^32 in a corrupt view.
  const std::uint64_t crc_word = std::uint64_t{image.address} + image.size - 4;
  if (magic != kImageCrcMagic || head_start < image.address || head_start > head_end ||
      head_end > body_start || body_start > body_end || body_end != crc_word) {
    return r;
  }
  Crc32 crc;
  Feed(crc, image.bytes + (head_start - image.address), head_end - head_start);
  Feed(crc, image.bytes + (body_start - image.address), body_end - body_start);
  r.trailer_valid = true;
  r.computed = crc.value();
  return r;
}

}  // namespace vibid::fw::stm32
