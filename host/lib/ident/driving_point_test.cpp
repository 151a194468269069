// The driving point from modal constants (methods §14) on exact constants: A_jr = phi_jr phi_pr
// from model::Modal's mass-normalised shapes of 2-, 3- and 4-mass chains hit on each mass; a
// named point the constants contradict is refused naming the one that fits; too few modes to
// tell is refused naming the candidates; a node at the hammer point is named with the mass to hit.
#include <gtest/gtest.h>

#include <optional>
#include <string>

#include "vibid/common/error.hpp"
#include "vibid/ident/driving_point.hpp"
#include "vibid/model/modal.hpp"
#include "vibid/model/model.hpp"

namespace vibid::ident {
namespace {

// The emulator's chain rigs' truths (host/emulator/rigs: default.json, chain3.json, chain4.json).
model::Model Chain(int n) {
  if (n == 2)
    return model::MakeChain(Eigen::Vector2d(2.0, 1.53), Eigen::Vector2d(3520.0, 2760.0),
                            Eigen::Vector2d(5.0, 3.5));
  if (n == 3)
    return model::MakeChain(Eigen::Vector3d(1.52, 1.2, 0.9), Eigen::Vector3d(3200, 2600, 2100),
                            Eigen::Vector3d(3.0, 2.0, 1.5));
  return model::MakeChain(Eigen::Vector4d(1.4, 1.2, 1.0, 0.8),
                          Eigen::Vector4d(4200, 3600, 3000, 2400), Eigen::Vector4d(3, 2.5, 2, 1.5));
}

// The receptance constants of the modes `modes` (all when empty) with the hammer at `p`.
ModalConstants ConstantsOf(const model::Model& m, Eigen::Index p, int modes = -1) {
  const model::ModalResult mr = model::Modal(m);
  const Eigen::Index n = mr.shapes.rows();
  const Eigen::Index used = modes < 0 ? n : modes;
  ModalConstants c;
  c.a.resize(n, used);
  for (Eigen::Index r = 0; r < used; ++r) {
    c.a.col(r) = mr.shapes.col(r) * mr.shapes(p, r);
    c.freq_hz.push_back(mr.omega_rad_s[r] / (2.0 * 3.141592653589793));
  }
  for (Eigen::Index j = 0; j < n; ++j) c.names.push_back("acc" + std::to_string(j + 1) + "_m_s2");
  return c;
}

std::string Refusal(const ModalConstants& c, const std::optional<NamedDrivingPoint>& named) {
  try {
    (void)ChooseDrivingPoint(c, named);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// Every mode there: the hammer point alone has positive constants in every mode (the cross
// points' sum to (M^-1)_ip = 0 over the modes, so some are negative), and its shapes give a
// diagonal mass matrix.
TEST(DrivingPoint, FoundOnChainsOfTwoToFourMassesHitOnEachMass) {
  for (int n = 2; n <= 4; ++n) {
    const model::Model m = Chain(n);
    for (Eigen::Index p = 0; p < n; ++p) {
      SCOPED_TRACE("n " + std::to_string(n) + " hit on mass " + std::to_string(p + 1));
      const ModalConstants c = ConstantsOf(m, p);
      const DrivingPointFinding f = FindDrivingPoint(c);
      ASSERT_TRUE(f.fits.has_value()) << f.why;
      EXPECT_EQ(*f.fits, static_cast<std::size_t>(p));
      EXPECT_LT(f.responses[static_cast<std::size_t>(p)].mass_coupling, 1e-9);
      for (Eigen::Index j = 0; j < n; ++j) {
        if (j != p) {
          EXPECT_FALSE(f.responses[static_cast<std::size_t>(j)].one_sign) << j;
        }
      }
      const DrivingPointChoice found = ChooseDrivingPoint(c, std::nullopt);
      EXPECT_EQ(found.index, static_cast<std::size_t>(p));
      EXPECT_EQ(found.how, "found");
      // Named rightly: kept.
      const DrivingPointChoice kept =
          ChooseDrivingPoint(c, NamedDrivingPoint{static_cast<std::size_t>(p), "--driving-point"});
      EXPECT_EQ(kept.index, static_cast<std::size_t>(p));
      EXPECT_EQ(kept.how, "named");
      // Named wrongly: refused, naming the one that fits.
      for (Eigen::Index q = 0; q < n; ++q) {
        if (q == p) continue;
        const std::string why =
            Refusal(c, NamedDrivingPoint{static_cast<std::size_t>(q),
                                         "--driving-point " + std::to_string(q + 1)});
        EXPECT_NE(why.find("the data fit acc" + std::to_string(p + 1) + "_m_s2"), std::string::npos)
            << why;
        EXPECT_NE(why.find("name response " + std::to_string(p + 1) + " as the driving point"),
                  std::string::npos)
            << why;
      }
    }
  }
}

// One mode of a three-mass chain: every response's constant is positive (mode 1 moves every mass
// one way), so the data cannot tell; not named, the choice is refused naming the way out; named,
// the name is kept.
TEST(DrivingPoint, OneModeCannotTellAndIsRefusedUnlessNamed) {
  const ModalConstants c = ConstantsOf(Chain(3), 2, 1);
  const DrivingPointFinding f = FindDrivingPoint(c);
  EXPECT_FALSE(f.fits.has_value());
  const std::string why = Refusal(c, std::nullopt);
  EXPECT_NE(why.find("name it (--driving-point NAME or INDEX"), std::string::npos) << why;
  EXPECT_NE(why.find("fewer modes than responses"), std::string::npos) << why;
  EXPECT_EQ(ChooseDrivingPoint(c, NamedDrivingPoint{0, "--driving-point 1"}).index, 0u);
}

// Constants of mixed sign everywhere (the hammer on a mass no response measures): refused, saying
// so.
TEST(DrivingPoint, NoResponseAtTheHammerIsRefused) {
  const model::Model m = Chain(4);
  ModalConstants all = ConstantsOf(m, 1);  // hit on mass 2 ...
  ModalConstants c;                        // ... measured on masses 1, 3 and 4
  c.a.resize(3, 4);
  c.a.row(0) = all.a.row(0);
  c.a.row(1) = all.a.row(2);
  c.a.row(2) = all.a.row(3);
  c.freq_hz = all.freq_hz;
  c.names = {"acc1_m_s2", "acc3_m_s2", "acc4_m_s2"};
  const std::string why = Refusal(c, std::nullopt);
  EXPECT_NE(why.find("the hammer was on a mass none of the responses measures"), std::string::npos)
      << why;
}

// A node at the hammer point: mode 2 of a symmetric shape (1, 0.03, -1) barely moves the middle
// mass, so its constant there is 0.03^2 of the largest; the mode is named with the mass to hit.
TEST(DrivingPoint, ANodeAtTheHammerPointNamesTheMassToHit) {
  Eigen::Matrix3d phi;
  phi << 0.5, 0.7, 0.4,  //
      0.6, 0.03, -0.6,   //
      0.5, -0.7, 0.4;
  ModalConstants c;
  c.a.resize(3, 3);
  for (int r = 0; r < 3; ++r) c.a.col(r) = phi.col(r) * phi(1, r);
  c.freq_hz = {3.0, 8.0, 12.0};
  c.names = {"a1", "a2", "a3"};
  const DrivingPointChoice choice = ChooseDrivingPoint(c, NamedDrivingPoint{1, "test"});
  ASSERT_EQ(choice.warnings.size(), 1u);
  EXPECT_NE(choice.warnings[0].find("mode 2 (8 Hz) has a node near the driving point"),
            std::string::npos)
      << choice.warnings[0];
  EXPECT_NE(choice.warnings[0].find("hit the mass a1 (response 1) measures"), std::string::npos)
      << choice.warnings[0];
}

}  // namespace
}  // namespace vibid::ident
