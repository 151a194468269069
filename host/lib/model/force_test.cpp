// Force shapes and tables.
#include "vibid/model/force.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "vibid/common/atomic_file.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/testing/input_error.hpp"

namespace vibid::model {
namespace {

std::string ErrorOf(const std::string& spec) {
  return InputErrorOf([&] { ParseForceShape(spec); });
}

TEST(ForceShape, ParsesEveryKindWithDefaults) {
  const ForceShape step = ParseForceShape("step:dof=1,amp=5");
  EXPECT_EQ(step.kind, ShapeKind::kStep);
  EXPECT_EQ(step.dof, 0);
  EXPECT_EQ(step.amp_n, 5.0);
  EXPECT_EQ(step.t0_s, 0.0);
  const ForceShape hammer = ParseForceShape("halfsine:dof=2,amp=100,t0=0.01,width=0.001");
  EXPECT_EQ(hammer.kind, ShapeKind::kHalfSine);
  EXPECT_EQ(hammer.dof, 1);
  EXPECT_EQ(hammer.t0_s, 0.01);
  EXPECT_EQ(hammer.width_s, 0.001);
  EXPECT_EQ(ParseForceShape("sine:dof=2,amp=1,freq_hz=16").freq_hz, 16.0);
  const ForceShape chirp = ParseForceShape("chirp:dof=1,amp=1,f0_hz=1,f1_hz=50,t1=10");
  EXPECT_EQ(chirp.f1_hz, 50.0);
  EXPECT_EQ(chirp.t1_s, 10.0);
  EXPECT_EQ(ParseForceShape("pulse: dof=1, amp=-5, width=0.1").amp_n, -5.0);
}

TEST(ForceShape, ValuesFollowTheDocumentedFormulas) {
  const ForceShape pulse = ParseForceShape("pulse:dof=1,amp=5,t0=0.2,width=0.1");
  EXPECT_EQ(EvaluateShape(pulse, 0.19), 0.0);
  EXPECT_EQ(EvaluateShape(pulse, 0.2), 5.0);
  EXPECT_EQ(EvaluateShape(pulse, 0.29), 5.0);
  EXPECT_EQ(EvaluateShape(pulse, 0.31), 0.0);
  const ForceShape hammer = ParseForceShape("halfsine:dof=1,amp=100,t0=0.01,width=0.002");
  EXPECT_NEAR(EvaluateShape(hammer, 0.011), 100.0, 1e-9);
  EXPECT_NEAR(EvaluateShape(hammer, 0.0105), 100.0 * std::sin(std::numbers::pi / 4.0), 1e-9);
  EXPECT_EQ(EvaluateShape(hammer, 0.0125), 0.0);
  const ForceShape sine = ParseForceShape("sine:dof=1,amp=2,freq_hz=4");
  EXPECT_NEAR(EvaluateShape(sine, 1.0 / 16.0), 2.0, 1e-12);
  // Linear chirp: instantaneous frequency f0 + (f1 − f0) τ / t1; phase 2π (f0 τ + (f1−f0) τ²/(2
  // t1)).
  const ForceShape chirp = ParseForceShape("chirp:dof=1,amp=1,f0_hz=1,f1_hz=3,t1=2");
  EXPECT_NEAR(EvaluateShape(chirp, 1.0), std::sin(2.0 * std::numbers::pi * (1.0 + 0.5)), 1e-12);
  EXPECT_EQ(EvaluateShape(chirp, 2.5), 0.0);
}

TEST(ForceShape, ErrorsNameTheProblem) {
  EXPECT_EQ(ErrorOf("ramp:dof=1,amp=1"),
            "force spec 'ramp:dof=1,amp=1': unknown kind 'ramp' (expected step, pulse, halfsine, "
            "sine or chirp)");
  EXPECT_EQ(ErrorOf("pulse:dof=1,amp=1"), "force spec 'pulse:dof=1,amp=1': missing key 'width'");
  EXPECT_EQ(ErrorOf("step:dof=1,amp=x"),
            "force spec 'step:dof=1,amp=x': amp='x' is not a finite number");
  EXPECT_EQ(ErrorOf("step:dof=1,amp=1,freq_hz=3"),
            "force spec 'step:dof=1,amp=1,freq_hz=3': unknown key 'freq_hz' for step");
  EXPECT_EQ(ErrorOf("step:dof=0,amp=1"),
            "force spec 'step:dof=0,amp=1': dof must be an integer >= 1 (counted from 1)");
  EXPECT_EQ(ErrorOf("step"),
            "force spec 'step': expected KIND:key=value,... with KIND one of step, pulse, "
            "halfsine, sine, chirp");
  EXPECT_EQ(ErrorOf("step:dof=1,dof=2,amp=1"),
            "force spec 'step:dof=1,dof=2,amp=1': key 'dof' given twice");
  EXPECT_EQ(ErrorOf("halfsine:dof=1,amp=1,width=0"),
            "force spec 'halfsine:dof=1,amp=1,width=0': width must be > 0 s");
}

TEST(ForceInput, SumsShapesAndHoldsTheTable) {
  ForceInput input;
  input.shapes.push_back(ParseForceShape("step:dof=2,amp=1"));
  input.table.t_s = Eigen::Vector3d(0.0, 0.1, 0.2);
  input.table.force_n =
      (Eigen::Matrix<double, 3, 2>() << 1.0, 10.0, 2.0, 20.0, 3.0, 30.0).finished();
  ValidateForceInput(input, 2);
  Eigen::VectorXd f(2);
  EvaluateForce(input, 0.15, f);
  EXPECT_EQ(f, Eigen::Vector2d(2.0, 21.0));
  EvaluateForce(input, 3.0 * 0.1, f);  // 0.30000000000000004: still the last row
  EXPECT_EQ(f, Eigen::Vector2d(3.0, 31.0));
  EvaluateForce(input, 0.7 - 0.5, f);  // 0.19999999999999996 is the 0.2 s sample's instant
  EXPECT_EQ(f, Eigen::Vector2d(3.0, 31.0));
  EvaluateForce(input, -0.01, f);
  EXPECT_EQ(f, Eigen::Vector2d(0.0, 0.0));
  EXPECT_THROW(ValidateForceInput(input, 3), InputError);
  input.table.t_s[2] = 0.1;
  EXPECT_THROW(ValidateForceInput(input, 2), InputError);
}

TEST(ForceTable, LoadsNamedColumns) {
  const std::string path = ::testing::TempDir() + "/force_table.csv";
  WriteFileAtomic(path, "t_s,f2_n\n0,1\n0.5,2\n");
  const ForceTable table = LoadForceTable(path, 2);
  EXPECT_EQ(table.force_n.col(0), Eigen::Vector2d(0.0, 0.0));
  EXPECT_EQ(table.force_n.col(1), Eigen::Vector2d(1.0, 2.0));
  WriteFileAtomic(path, "t_s,f3_n\n0,1\n");
  EXPECT_THROW(LoadForceTable(path, 2), InputError);
  WriteFileAtomic(path, "time,f1_n\n0,1\n");
  EXPECT_THROW(LoadForceTable(path, 2), InputError);
}

}  // namespace
}  // namespace vibid::model
