// The verdict a result carries: levels only rise, the JSON form reads back, a malformed one is
// refused, and RequireUsable refuses a flagged input unless it is accepted.
#include <gtest/gtest.h>

#include <string>

#include <nlohmann/json.hpp>

#include "vibid/common/testing/input_error.hpp"
#include "vibid/common/verdict.hpp"

namespace vibid {
namespace {

Verdict Flagged() {
  Verdict v;
  v.Add(VerdictLevel::kCaution, "chain_fit_unchecked", "no intervals");
  v.Add(VerdictLevel::kFlagged, "worse_than_nominal", "fits worse than the nominal");
  return v;
}

TEST(Verdict, LevelRisesToItsWorstReasonAndNeverFalls) {
  Verdict v;
  EXPECT_EQ(v.level, VerdictLevel::kOk);
  v.Add(VerdictLevel::kFlagged, "a", "x");
  v.Add(VerdictLevel::kCaution, "b", "y");
  EXPECT_EQ(v.level, VerdictLevel::kFlagged);
  EXPECT_TRUE(v.Flagged());
  EXPECT_TRUE(v.Has("b"));
  EXPECT_FALSE(v.Has("c"));
}

TEST(Verdict, NamesReadBack) {
  for (const VerdictLevel l :
       {VerdictLevel::kOk, VerdictLevel::kCaution, VerdictLevel::kFlagged, VerdictLevel::kRefused})
    EXPECT_EQ(ParseVerdictLevel(VerdictLevelName(l)), l);
  EXPECT_EQ(ParseVerdictLevel("FLAGGED"), std::nullopt);  // the file's spelling is lower case
}

TEST(Verdict, JsonRoundTrip) {
  const Verdict v = Flagged();
  const nlohmann::json j = VerdictToJson(v);
  EXPECT_EQ(j["level"], "flagged");
  EXPECT_EQ(j["reasons"][1]["code"], "worse_than_nominal");
  const Verdict back = VerdictFromJson(j, "x.json: field \"verdict\"");
  EXPECT_EQ(back.level, VerdictLevel::kFlagged);
  ASSERT_EQ(back.reasons.size(), 2u);
  EXPECT_EQ(back.reasons[0].level, VerdictLevel::kCaution);
  EXPECT_EQ(back.reasons[1].text, "fits worse than the nominal");
  EXPECT_TRUE(back.stated);
}

TEST(Verdict, MalformedJsonIsRefusedNamingWhere) {
  const std::string where = "m.json: field \"verdict\"";
  EXPECT_EQ(InputErrorOf([&] {
              VerdictFromJson(nlohmann::json{{"level", "fine"}}, where);
            }),
            where + ": \"level\" 'fine' is not one of ok, caution, flagged, refused");
  EXPECT_NE(InputErrorOf([&] {
              VerdictFromJson(nlohmann::json{{"level", "ok"}, {"reason", nlohmann::json::array()}},
                              where);
            }).find("unknown key 'reason'"),
            std::string::npos);
  // A stated level below its reasons' is a contradiction, not a level to guess.
  nlohmann::json lowered = VerdictToJson(Flagged());
  lowered["level"] = "ok";
  EXPECT_NE(InputErrorOf([&] { VerdictFromJson(lowered, where); }).find("below its reasons"),
            std::string::npos);
}

TEST(Verdict, FormatsLevelAndReasons) {
  EXPECT_EQ(FormatVerdict(Flagged()), "FLAGGED: no intervals; fits worse than the nominal");
  EXPECT_EQ(FormatVerdict(Verdict{}), "OK");
  Verdict none;
  none.stated = false;
  EXPECT_EQ(FormatVerdict(none), "OK (none stated)");
}

TEST(RequireUsable, RefusesFlaggedUnlessAcceptedNamingTheOption) {
  std::string caught;
  try {
    RequireUsable(Flagged(), false, "model file u.json", "cal upload", "--accept-flagged");
  } catch (const FlaggedError& e) {
    caught = e.what();
  }
  EXPECT_EQ(caught,
            "model file u.json is flagged (fits worse than the nominal): cal upload refuses it; "
            "--accept-flagged takes it anyway, or identify again");
  EXPECT_NO_THROW(
      RequireUsable(Flagged(), true, "model file u.json", "cal upload", "--accept-flagged"));
  Verdict caution;
  caution.Add(VerdictLevel::kCaution, "c", "unchecked");
  EXPECT_NO_THROW(RequireUsable(caution, false, "m", "s", "o"));
  Verdict refused;
  refused.Add(VerdictLevel::kRefused, "r", "no result");
  EXPECT_THROW(RequireUsable(refused, true, "m", "s", "o"), FlaggedError);
}

}  // namespace
}  // namespace vibid
