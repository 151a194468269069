// vibid flash IMAGE.bin: the application asks the board into its DfuSe bootloader (enter-DFU), the
// host erases the sectors the image covers, downloads it, reads it back byte for byte and leaves
// the bootloader, which starts the new firmware.
#include <chrono>
#include <cstdio>
#include <optional>
#include <iostream>

#include "cli_support.hpp"
#include "common/command.hpp"
#include "vibid/common/option_text.hpp"
#include "device_commands.hpp"
#include "session.hpp"
#include "vibid/common/atomic_file.hpp"
#include "vibid/common/error.hpp"
#include "vibid/device/flash_board.hpp"

namespace vibid::cli {
namespace {

constexpr std::uint32_t kFlashBase = 0x08000000u;

constexpr const char* kFlashHelp =
    "Write a firmware image through the DfuSe bootloader and verify it";

struct FlashArgs {
  const GlobalOptions* globals = nullptr;
  std::string image;
  std::string address = "0x08000000";
};

void Run(const FlashArgs& a) {
  const std::string text = ReadFileText(a.image);
  const std::vector<std::uint8_t> image(text.begin(), text.end());
  const std::optional<long long> address = ParseInteger(a.address, 0);
  Require(address && *address >= kFlashBase && *address <= 0xFFFFFFFFll,
          "--address '" + a.address + "' must be a flash address from 0x08000000");
  const device::DeviceSpec spec = ChosenDevice(*a.globals);
  ProgressBar erase("erase"), download("download"), verify("verify");
  const device::FlashProgress progress = [&](const std::string& phase, std::uint64_t done,
                                             std::uint64_t total) {
    (phase == "erase" ? erase : phase == "download" ? download : verify).Update(done, total);
  };
  const auto started = std::chrono::steady_clock::now();
  device::FlashBoardResult result;
  try {
    result =
        device::FlashBoard(spec, image, static_cast<std::uint32_t>(*address), progress,
                           [](const std::string& note) { std::cerr << "vibid: " << note << "\n"; });
  } catch (const InputError& e) {
    throw InputError(a.image + ": " + e.what());
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  std::uint64_t written = 0;
  for (const device::FlashRange& r : result.plan.write) written += r.bytes;
  char line[200];
  std::snprintf(line, sizeof(line),
                "flashed %zu bytes at %s in %.2f s (%llu written, %zu sectors erased, calibration "
                "kept), verified; the board restarts\n",
                image.size(), a.address.c_str(), seconds, static_cast<unsigned long long>(written),
                result.plan.erase.size());
  std::cout << line;
}

}  // namespace

void RegisterFlashCommand(CLI::App& app, const GlobalOptions& globals) {
  const auto [flash, o] = AddCommand<FlashArgs>(app, "flash", kFlashHelp, Run);
  o->globals = &globals;
  TakesDeviceOption(flash);
  flash->add_option("image", o->image, "Raw image (.bin)")->required();
  flash->add_option("--address", o->address, "Flash address of the image's first byte")
      ->capture_default_str();
}

}  // namespace vibid::cli
