// The emulated STM32F405's 1 MiB internal flash, optionally backed by a file.
//
// Layout as on the board (RM0090 §3.3): sectors 0-3 of 16 KiB, sector 4 of 64 KiB, sectors 5-11
// of 128 KiB, from 0x08000000. The calibration slots live in sectors 2 and 3 exactly as on the
// board; the DfuSe bootloader writes the firmware image wherever the host addresses it.
// NOR semantics: erase sets a whole sector to 0xFF, programming can only clear bits.
//
// With a file, every erase and program is written through to it atomically (write a temporary
// copy, rename), so a crash never leaves a half-written image and calibration survives restarts.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "emu_port.hpp"

namespace vibid::emu {

class FlashImage final : public FlashArray {
 public:
  static constexpr std::uint32_t kBase = 0x08000000u;
  static constexpr std::size_t kBytes = 1024 * 1024;
  static constexpr int kSectorCount = 12;
  static constexpr std::uint8_t kErased = 0xFF;

  /// `path` empty: the flash lives in memory for the process lifetime. Otherwise the file is
  /// read if it exists (it must be exactly kBytes long) or created erased.
  /// @throws InputError naming the file if it cannot be read, has the wrong size, or cannot be
  ///         written.
  explicit FlashImage(std::string path);

  /// Start address and size of a sector (0..11).
  static std::uint32_t SectorStart(int sector);
  static std::size_t SectorBytes(int sector);
  /// The sector holding `address`, or nullopt outside the flash.
  static std::optional<int> SectorOf(std::uint32_t address);
  /// True when [address, address + bytes) lies inside the flash.
  static bool Contains(std::uint32_t address, std::size_t bytes);

  /// Erases one sector (0..11); false for an invalid sector.
  bool EraseSector(int sector) override;
  /// Programs bytes (new = old AND data). @returns false when the range is outside the flash or
  /// the read-back differs from `data` (the target was not erased), as the controller's verify
  /// would report.
  bool Program(std::uint32_t address, std::span<const std::uint8_t> data) override;
  /// Reads bytes; false when the range is outside the flash.
  bool Read(std::uint32_t address, std::span<std::uint8_t> out) const override;

  const std::string& path() const { return path_; }
  std::span<const std::uint8_t> bytes() const { return bytes_; }

 private:
  void Persist() const;

  std::string path_;
  std::vector<std::uint8_t> bytes_;
};

}  // namespace vibid::emu
