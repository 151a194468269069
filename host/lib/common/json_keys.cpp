#include "vibid/common/json_keys.hpp"

#include <algorithm>
#include <cctype>
#include <vector>

#include "vibid/common/error.hpp"
#include "vibid/common/text_input.hpp"

namespace vibid {
namespace {

char Lower(char c) { return static_cast<char>(std::tolower(static_cast<unsigned char>(c))); }

// Optimal string alignment distance: insertions, deletions, substitutions and swaps of two
// neighbours each cost 1 (a swap is the commonest typing slip).
std::size_t EditDistance(std::string_view a, std::string_view b) {
  const std::size_t n = a.size(), m = b.size();
  std::vector<std::vector<std::size_t>> d(n + 1, std::vector<std::size_t>(m + 1));
  for (std::size_t i = 0; i <= n; ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= m; ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= n; ++i) {
    for (std::size_t j = 1; j <= m; ++j) {
      const std::size_t cost = Lower(a[i - 1]) == Lower(b[j - 1]) ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && Lower(a[i - 1]) == Lower(b[j - 2]) &&
          Lower(a[i - 2]) == Lower(b[j - 1]))
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  }
  return d[n][m];
}

}  // namespace

namespace {

template <typename Names>
std::string Nearest(std::string_view name, const Names& known) {
  // Keys are short; past 64 characters the text is no slip of the keyboard (and the distance
  // table stays small for any input).
  if (name.size() > 64) return {};
  std::string best;
  std::size_t best_distance = 0;
  for (const std::string_view k : known) {
    const std::size_t distance = EditDistance(name, k);
    // Near: at most a third of the longer name changed (one slip in a short key), and the key
    // shares something with the name (not every 2-letter key is near every other).
    const std::size_t longer = std::max(name.size(), k.size());
    if (distance > std::max<std::size_t>(1, longer / 3) || distance >= longer) continue;
    if (best.empty() || distance < best_distance) {
      best = std::string(k);
      best_distance = distance;
    }
  }
  return best;
}

}  // namespace

std::string NearestName(std::string_view name, std::initializer_list<std::string_view> known) {
  return Nearest(name, known);
}

std::string NearestName(std::string_view name, const std::vector<std::string>& known) {
  return Nearest(name, known);
}

void RequireKnownKeys(const nlohmann::json& object, std::initializer_list<std::string_view> known,
                      const std::string& what) {
  if (!object.is_object()) return;
  for (const auto& item : object.items()) {
    const std::string& key = item.key();
    if (std::find(known.begin(), known.end(), std::string_view(key)) != known.end()) continue;
    const std::string nearest = NearestName(key, known);
    std::string hint;
    if (!nearest.empty()) {
      hint = " (did you mean '" + nearest + "'?)";
    } else {
      for (const std::string_view k : known) hint += (hint.empty() ? "" : ", ") + std::string(k);
      hint = " (valid keys: " + hint + ")";
    }
    throw InputError("unknown key '" + Printable(key) + "' in " + what + hint);
  }
}

}  // namespace vibid
