// The page's files, embedded into the program at build time (embed_assets.cmake): the bench runs
// with no network and no files beside it.
#pragma once

#include <span>
#include <string_view>

namespace vibid::bench {

struct Asset {
  std::string_view path;  ///< As served: "/assets/bench.js".
  std::string_view content_type;
  std::string_view bytes;
};

std::span<const Asset> Assets();

/// The asset at `path`, or null.
const Asset* FindAsset(std::string_view path);

}  // namespace vibid::bench
