#include "flash_image.hpp"

#include <algorithm>
#include <fstream>
#include <iterator>
#include <string_view>

#include "vibid/common/atomic_file.hpp"
#include "vibid/common/error.hpp"

namespace vibid::emu {

FlashImage::FlashImage(std::string path) : path_(std::move(path)), bytes_(kBytes, kErased) {
  if (path_.empty()) return;
  std::ifstream in(path_, std::ios::binary);
  if (!in) {
    Persist();  // a new board: fully erased
    return;
  }
  std::vector<std::uint8_t> content((std::istreambuf_iterator<char>(in)),
                                    std::istreambuf_iterator<char>());
  Require(content.size() == kBytes, "flash file '" + path_ + "' is " +
                                        std::to_string(content.size()) + " bytes, not the " +
                                        std::to_string(kBytes) + " of the board's flash");
  bytes_ = std::move(content);
}

std::uint32_t FlashImage::SectorStart(int sector) {
  if (sector < 4) return kBase + static_cast<std::uint32_t>(sector) * 0x4000u;
  if (sector == 4) return kBase + 0x10000u;
  return kBase + 0x20000u + static_cast<std::uint32_t>(sector - 5) * 0x20000u;
}

std::size_t FlashImage::SectorBytes(int sector) {
  if (sector < 4) return 16 * 1024;
  if (sector == 4) return 64 * 1024;
  return 128 * 1024;
}

std::optional<int> FlashImage::SectorOf(std::uint32_t address) {
  for (int s = 0; s < kSectorCount; ++s) {
    if (address >= SectorStart(s) && address - SectorStart(s) < SectorBytes(s)) return s;
  }
  return std::nullopt;
}

bool FlashImage::Contains(std::uint32_t address, std::size_t bytes) {
  return address >= kBase && address - kBase <= kBytes && bytes <= kBytes - (address - kBase);
}

bool FlashImage::EraseSector(int sector) {
  if (sector < 0 || sector >= kSectorCount) return false;
  const auto begin = bytes_.begin() + (SectorStart(sector) - kBase);
  std::fill(begin, begin + static_cast<std::ptrdiff_t>(SectorBytes(sector)), kErased);
  Persist();
  return true;
}

bool FlashImage::Program(std::uint32_t address, std::span<const std::uint8_t> data) {
  if (!Contains(address, data.size())) return false;
  std::uint8_t* at = bytes_.data() + (address - kBase);
  bool verified = true;
  for (std::size_t i = 0; i < data.size(); ++i) {
    at[i] = static_cast<std::uint8_t>(at[i] & data[i]);
    verified = verified && at[i] == data[i];
  }
  Persist();
  return verified;
}

bool FlashImage::Read(std::uint32_t address, std::span<std::uint8_t> out) const {
  if (!Contains(address, out.size())) return false;
  std::copy_n(bytes_.begin() + (address - kBase), out.size(), out.begin());
  return true;
}

void FlashImage::Persist() const {
  if (path_.empty()) return;
  WriteFileAtomic(path_,
                  std::string_view(reinterpret_cast<const char*>(bytes_.data()), bytes_.size()));
}

}  // namespace vibid::emu
