// Model building, validation and model files.
#include "vibid/model/model.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "vibid/common/error.hpp"
#include "vibid/common/testing/input_error.hpp"
#include "vibid/model/model_json.hpp"

namespace vibid::model {
namespace {

using nlohmann::json;

std::string ErrorOf(const json& j) {
  return InputErrorOf([&] { ModelFromJson(j, "rig.json"); });
}

TEST(MakeChain, TwoDofMatchesMethodsSection1) {
  // Methods §1: K = [[k1+k2, −k2], [−k2, k2]], M = diag(m1, m2); dampers assemble the same way.
  const Model m = MakeChain(Eigen::Vector2d(2.0, 1.5), Eigen::Vector2d(4000.0, 3000.0),
                            Eigen::Vector2d(2.0, 1.0));
  EXPECT_EQ(m.m_kg, (Eigen::Matrix2d() << 2.0, 0.0, 0.0, 1.5).finished());
  EXPECT_EQ(m.k_n_per_m, (Eigen::Matrix2d() << 7000.0, -3000.0, -3000.0, 3000.0).finished());
  EXPECT_EQ(m.c_ns_per_m, (Eigen::Matrix2d() << 3.0, -1.0, -1.0, 1.0).finished());
}

TEST(MakeChain, ThreeDofIsTridiagonalAndUndampedWithoutDampers) {
  const Model m = MakeChain(Eigen::Vector3d(1.0, 2.0, 3.0), Eigen::Vector3d(10.0, 20.0, 30.0));
  Eigen::Matrix3d k;
  k << 30.0, -20.0, 0.0, -20.0, 50.0, -30.0, 0.0, -30.0, 30.0;
  EXPECT_EQ(m.k_n_per_m, k);
  EXPECT_TRUE(m.c_ns_per_m.isZero(0.0));
  EXPECT_EQ(m.dofs(), 3);
}

TEST(MakeChain, RejectsMismatchedCountsAndBadValues) {
  EXPECT_THROW(MakeChain(Eigen::Vector2d(1.0, 1.0), Eigen::VectorXd::Constant(1, 5.0)), InputError);
  EXPECT_THROW(MakeChain(Eigen::Vector2d(1.0, 1.0), Eigen::Vector2d(5.0, 5.0),
                         Eigen::VectorXd::Constant(1, 1.0)),
               InputError);
  EXPECT_THROW(MakeChain(Eigen::Vector2d(1.0, 0.0), Eigen::Vector2d(5.0, 5.0)), InputError);
  EXPECT_THROW(MakeChain(Eigen::Vector2d(1.0, 1.0), Eigen::Vector2d(5.0, -5.0)), InputError);
}

TEST(MakeCartTrack, TwoCartsHaveThreeEqualSprings) {
  // ground –k– M1 –k– M2 –k– ground: K = [[2k, −k], [−k, 2k]], C = diag(B1, B2).
  const Model m = MakeCartTrack(Eigen::Vector2d(0.57, 0.56), 15.0, Eigen::Vector2d(0.4, 0.3));
  EXPECT_EQ(m.k_n_per_m, (Eigen::Matrix2d() << 30.0, -15.0, -15.0, 30.0).finished());
  EXPECT_EQ(m.c_ns_per_m, (Eigen::Matrix2d() << 0.4, 0.0, 0.0, 0.3).finished());
  EXPECT_EQ(m.m_kg, (Eigen::Matrix2d() << 0.57, 0.0, 0.0, 0.56).finished());
}

TEST(CartPositionInput, IsBiTimesRatePlusTwoK) {
  // Methods §1: F(s) = (Bi s + 2k) Xi(s), i.e. F = Bi dXi/dt + 2k Xi.
  EXPECT_DOUBLE_EQ(CartPositionInputForce(15.0, 0.5, 0.02, 0.3), 0.5 * 0.3 + 2.0 * 15.0 * 0.02);
}

TEST(Validate, AcceptsSemidefiniteK) {
  Model free_free;
  free_free.m_kg = Eigen::Matrix2d::Identity();
  free_free.k_n_per_m = (Eigen::Matrix2d() << 1.0, -1.0, -1.0, 1.0).finished();
  free_free.c_ns_per_m = Eigen::Matrix2d::Zero();
  EXPECT_NO_THROW(Validate(free_free));
}

TEST(Validate, RejectsEachDefect) {
  const Model good = MakeChain(Eigen::Vector2d(2.0, 1.5), Eigen::Vector2d(4000.0, 3000.0));
  const auto message = [](const Model& m) { return InputErrorOf([&] { Validate(m); }); };
  Model m = good;
  m.m_kg(0, 1) = 0.5;
  EXPECT_EQ(message(m), "M is not symmetric");
  m = good;
  m.k_n_per_m(1, 0) = 1.0;
  EXPECT_EQ(message(m), "K is not symmetric");
  m = good;
  m.m_kg(1, 1) = -1.0;
  EXPECT_EQ(message(m), "M is not positive definite");
  m = good;
  m.m_kg << 1.0, 2.0, 2.0, 1.0;  // symmetric, indefinite (eigenvalues 3, −1)
  EXPECT_EQ(message(m), "M is not positive definite");
  m = good;
  m.k_n_per_m << 1.0, 2.0, 2.0, 1.0;
  EXPECT_NE(message(m).find("K is not positive semidefinite"), std::string::npos);
  m = good;
  m.k_n_per_m(0, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(message(m), "K has a non-finite entry");
  m = good;
  m.c_ns_per_m = Eigen::Matrix3d::Zero();
  EXPECT_EQ(message(m), "C must be 2x2 like M, got 3x3");
  m = good;
  m.m_kg.resize(0, 0);
  EXPECT_EQ(message(m), "model has no degrees of freedom (M is empty)");
  EXPECT_EQ(message(good), "");
}

TEST(ModelJson, ChainCartAndMatrixFormsBuildTheSameModelsAsTheBuilders) {
  const Model chain = ModelFromJson(json::parse(
      R"({"topology":"chain","masses":[2.0,1.5],"springs":[4000,3000],"dampers":[2,1]})"));
  const Model chain_ref = MakeChain(Eigen::Vector2d(2.0, 1.5), Eigen::Vector2d(4000.0, 3000.0),
                                    Eigen::Vector2d(2.0, 1.0));
  EXPECT_EQ(chain.k_n_per_m, chain_ref.k_n_per_m);
  EXPECT_EQ(chain.c_ns_per_m, chain_ref.c_ns_per_m);
  EXPECT_EQ(chain.m_kg, chain_ref.m_kg);

  const Model cart = ModelFromJson(
      json::parse(R"({"topology":"cart","masses":[0.57,0.56],"spring":15,"frictions":[0.4,0.3]})"));
  EXPECT_EQ(cart.k_n_per_m,
            MakeCartTrack(Eigen::Vector2d(0.57, 0.56), 15.0, Eigen::Vector2d(0.4, 0.3)).k_n_per_m);
  EXPECT_EQ(cart.c_ns_per_m(1, 1), 0.3);

  const Model full =
      ModelFromJson(json::parse(R"({"M":[[2,0],[0,1.5]],"K":[[7000,-3000],[-3000,3000]]})"));
  EXPECT_EQ(full.k_n_per_m, chain_ref.k_n_per_m);
  EXPECT_TRUE(full.c_ns_per_m.isZero(0.0));
}

TEST(ModelJson, RoundTripIsBitExact) {
  Model m;
  m.m_kg = (Eigen::Matrix2d() << 2.0 / 3.0, 0.1, 0.1, 1.0 / 7.0).finished();
  m.k_n_per_m = (Eigen::Matrix2d() << 7000.123456789, -3000.1, -3000.1, 3000.3).finished();
  m.c_ns_per_m = (Eigen::Matrix2d() << 1e-7, 0.0, 0.0, 3.3).finished();
  const Model back = ModelFromJson(json::parse(ModelToJson(m).dump()));
  EXPECT_EQ(back.m_kg, m.m_kg);
  EXPECT_EQ(back.k_n_per_m, m.k_n_per_m);
  EXPECT_EQ(back.c_ns_per_m, m.c_ns_per_m);
}

TEST(ModelJson, ErrorsNameTheSourceAndField) {
  EXPECT_EQ(ErrorOf(json::parse(R"([1,2])")), "rig.json: a model must be a JSON object");
  EXPECT_EQ(ErrorOf(json::parse(R"({"topology":"chain","springs":[1]})")),
            "rig.json: field \"masses\" is missing");
  EXPECT_EQ(ErrorOf(json::parse(R"({"topology":"chain","masses":[1,"a"],"springs":[1,1]})")),
            "rig.json: field \"masses\"[2] must be a number");
  EXPECT_EQ(ErrorOf(json::parse(R"({"topology":"ring","masses":[1]})")),
            "rig.json: field \"topology\" is \"ring\"; expected \"chain\" or \"cart\"");
  EXPECT_EQ(ErrorOf(json::parse(R"({"topology":"cart","masses":[1]})")),
            "rig.json: field \"spring\" is missing");
  EXPECT_EQ(ErrorOf(json::parse(R"({"topology":"chain","masses":[1,1],"springs":[1]})")),
            "rig.json: chain has 2 masses but 1 springs (need one per mass)");
  EXPECT_EQ(ErrorOf(json::parse(R"({"M":[[1,0],[0]],"K":[[1,0],[0,1]]})")),
            "rig.json: field \"M\" row 2 has 1 entries, row 1 has 2");
  EXPECT_EQ(ErrorOf(json::parse(R"({"M":[[1,0],[0,1]],"K":[[1]]})")),
            "rig.json: K must be 2x2 like M, got 1x1");
  EXPECT_EQ(ErrorOf(json::parse(R"({"M":[[1,0],[0,-1]],"K":[[1,0],[0,1]]})")),
            "rig.json: M is not positive definite");
  EXPECT_EQ(ErrorOf(json::parse(R"({"K":[[1]]})")),
            "rig.json: a model needs \"topology\" (chain or cart) or the matrices \"M\" and \"K\"");
}

TEST(ModelJson, RefusesUnknownKeysNamingTheNearestOne) {
  // A misspelt optional field used to load as an undamped chain.
  EXPECT_EQ(ErrorOf(json::parse(
                R"({"topology":"chain","masses":[2,1.5],"springs":[4000,3000],"damper":[6,4.5]})")),
            "unknown key 'damper' in model file rig.json (did you mean 'dampers'?)");
  EXPECT_EQ(
      ErrorOf(json::parse(R"({"topology":"cart","masses":[1],"spring":15,"friction":[0.4]})")),
      "unknown key 'friction' in model file rig.json (did you mean 'frictions'?)");
  EXPECT_EQ(ErrorOf(json::parse(R"({"M":[[1]],"K":[[1]],"c":[[1]]})")),
            "unknown key 'c' in model file rig.json (did you mean 'C'?)");
  EXPECT_EQ(ErrorOf(json::parse(R"({"topolgy":"chain","masses":[1],"springs":[1]})")),
            "unknown key 'topolgy' in model file rig.json (did you mean 'topology'?)");
  // A key of another form is unknown in this one.
  EXPECT_EQ(ErrorOf(json::parse(R"({"topology":"chain","masses":[1],"springs":[1],"spring":1})")),
            "unknown key 'spring' in model file rig.json (did you mean 'springs'?)");
  EXPECT_EQ(ErrorOf(json::parse(R"({"M":[[1]],"K":[[1]],"masses":[1]})")),
            "unknown key 'masses' in model file rig.json (valid keys: M, C, K, verdict)");
}

}  // namespace
}  // namespace vibid::model
