// The image's own CRC-32 against the one the build wrote into its trailer (sections.ld,
// ".image_crc"; image_crc.py stamps it after the link): the self-test's image-crc check.
#pragma once

#include <cstddef>
#include <cstdint>

extern "C" {
/// The trailer's first byte (sections.ld): six little-endian words, the last the stored CRC.
extern const std::uint8_t __image_crc_trailer[];  // NOLINT(bugprone-reserved-identifier)
}

namespace vibid::fw::stm32 {

/// "vCRC" read as a little-endian word.
inline constexpr std::uint32_t kImageCrcMagic = 0x43524376;
inline constexpr std::size_t kImageCrcTrailerBytes = 24;

/// Image bytes from `address` up to and including the trailer, which are its last 24 bytes;
/// `bytes` points at `address` (the flash itself on the chip, a copy in the host tests).
struct ImageView {
  const std::uint8_t* bytes = nullptr;
  std::uint32_t address = 0;
  std::size_t size = 0;
};

struct ImageCrcResult {
  bool trailer_valid = false;  ///< Magic, ranges in order and inside the view, CRC word last.
  std::uint32_t computed = 0;  ///< CRC-32 of head then body (valid trailer only).
  std::uint32_t stored = 0;    ///< The trailer's CRC word.
};

/// Checks the trailer as image_crc.py does (magic "vCRC", head_start <= head_end <= body_start
/// <= body_end, body_end the CRC word's own address, head_start no lower than the view) and
/// computes CRC-32/ISO-HDLC (vibid::Crc32, the log pull's table, 1 KiB already in the image) of
/// [head_start, head_end) then [body_start, body_end), feeding the watchdog every 16 KiB.
ImageCrcResult CheckImageCrc(const ImageView& image);

/// The image this code runs from: flash from the head's start (the vector table at 0x08000000)
/// to the end of the linker's trailer. Only on the chip (the trailer symbol is the linker's).
inline ImageView OwnImage() {
  constexpr std::uint32_t kFlashBase = 0x08000000;
  const auto trailer =
      static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(__image_crc_trailer));
  return {.bytes = reinterpret_cast<const std::uint8_t*>(std::uintptr_t{kFlashBase}),
          .address = kFlashBase,
          .size = trailer + kImageCrcTrailerBytes - kFlashBase};
}

}  // namespace vibid::fw::stm32
