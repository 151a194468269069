// Unknown keys in JSON files: refused with the nearest valid key named.
#include <gtest/gtest.h>

#include <string>

#include <nlohmann/json.hpp>

#include "vibid/common/json_keys.hpp"
#include "vibid/common/testing/input_error.hpp"

namespace vibid {
namespace {

std::string KeyError(const char* text) {
  return InputErrorOf([&] {
    RequireKnownKeys(nlohmann::json::parse(text), {"topology", "masses", "springs", "dampers"},
                     "model file x.json");
  });
}

TEST(RequireKnownKeys, AcceptsKnownKeysInAnyOrderAndSubsets) {
  EXPECT_EQ(KeyError(R"({"dampers": [1], "topology": "chain"})"), "");
  EXPECT_EQ(KeyError("{}"), "");
  EXPECT_EQ(KeyError("[1, 2]"), "");  // not an object: the reader says what it expected
}

TEST(RequireKnownKeys, NamesTheNearestKey) {
  // One letter missing, one extra, one swapped pair, another case: each one edit away.
  EXPECT_EQ(KeyError(R"({"topology": "chain", "damper": [1]})"),
            "unknown key 'damper' in model file x.json (did you mean 'dampers'?)");
  EXPECT_EQ(KeyError(R"({"massess": [1]})"),
            "unknown key 'massess' in model file x.json (did you mean 'masses'?)");
  EXPECT_EQ(KeyError(R"({"sprnigs": [1]})"),
            "unknown key 'sprnigs' in model file x.json (did you mean 'springs'?)");
  EXPECT_EQ(KeyError(R"({"Topology": "chain"})"),
            "unknown key 'Topology' in model file x.json (did you mean 'topology'?)");
}

TEST(RequireKnownKeys, ListsTheValidKeysWhenNoneIsNear) {
  EXPECT_EQ(KeyError(R"({"comment": "rig 2"})"),
            "unknown key 'comment' in model file x.json (valid keys: topology, masses, springs, "
            "dampers)");
  // Control characters in a key are escaped, not printed raw.
  EXPECT_EQ(KeyError("{\"a\\u001bb\": 1}"),
            "unknown key 'a\\x1Bb' in model file x.json (valid keys: topology, masses, springs, "
            "dampers)");
}

TEST(NearestName, OneLetterKeysAreNotNearEachOther) {
  EXPECT_EQ(NearestName("C", {"M", "K"}), "");
  EXPECT_EQ(NearestName("k", {"M", "K"}), "K");
  EXPECT_EQ(NearestName("rnage_n", {"range_n", "noise_n", "adc_bits"}), "range_n");
  EXPECT_EQ(NearestName("x", {"masses", "springs"}), "");
}

}  // namespace
}  // namespace vibid
