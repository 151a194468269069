#include "vibid/numerics/least_squares.hpp"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <string>

#include "vibid/common/error.hpp"

namespace vibid::numerics {
namespace {

// y = a exp(-b t) sampled on [0, 2]: a small, well-posed nonlinear fit with a known answer.
struct ExpDecay {
  Eigen::VectorXd t_s = Eigen::VectorXd::LinSpaced(40, 0.0, 2.0);
  Eigen::VectorXd y;
  ExpDecay(double a, double b_per_s) : y((-b_per_s * t_s.array()).exp() * a) {}

  bool Residuals(const Eigen::VectorXd& x, Eigen::VectorXd& r) const {
    r = x[0] * (-x[1] * t_s.array()).exp().matrix() - y;
    return true;
  }
  bool WithJacobian(const Eigen::VectorXd& x, Eigen::VectorXd& r, Eigen::MatrixXd* jac) const {
    Residuals(x, r);
    if (jac != nullptr) {
      const Eigen::ArrayXd e = (-x[1] * t_s.array()).exp();
      jac->resize(t_s.size(), 2);
      jac->col(0) = e.matrix();
      jac->col(1) = (-x[0] * t_s.array() * e).matrix();
    }
    return true;
  }
  /// The residuals with the analytic Jacobian, as the solver takes them.
  ResidualFunction Analytic() const {
    return [this](const Eigen::VectorXd& x, Eigen::VectorXd& r, Eigen::MatrixXd* jac) {
      return WithJacobian(x, r, jac);
    };
  }
};

TEST(LevenbergMarquardt, AnalyticJacobianFindsTheExactFit) {
  const ExpDecay problem(2.5, 1.3);
  Eigen::VectorXd x(2);
  x << 1.0, 0.2;
  const SolverSummary s = LevenbergMarquardt(problem.Analytic(), x, SolverOptions{});
  ASSERT_TRUE(s.Converged()) << s.message;
  EXPECT_NEAR(x[0], 2.5, 1e-9);
  EXPECT_NEAR(x[1], 1.3, 1e-9);
  EXPECT_LT(s.final_cost, s.initial_cost);
  EXPECT_LT(s.final_cost, 1e-20);
}

TEST(LevenbergMarquardt, NumericDiffMatchesTheAnalyticJacobian) {
  const ExpDecay problem(0.7, 4.0);
  const ResidualFunction numeric = NumericDiff(
      [&](const Eigen::VectorXd& p, Eigen::VectorXd& r) { return problem.Residuals(p, r); });
  Eigen::VectorXd x(2);
  x << 1.0, 1.0;
  Eigen::VectorXd r;
  Eigen::MatrixXd j_numeric;
  Eigen::MatrixXd j_analytic;
  ASSERT_TRUE(numeric(x, r, &j_numeric));
  ASSERT_TRUE(problem.WithJacobian(x, r, &j_analytic));
  EXPECT_LT((j_numeric - j_analytic).cwiseAbs().maxCoeff(), 1e-8);

  Solution final;
  const SolverSummary s = LevenbergMarquardt(numeric, x, SolverOptions{}, &final);
  ASSERT_TRUE(s.Converged()) << s.message;
  EXPECT_NEAR(x[0], 0.7, 1e-8);
  EXPECT_NEAR(x[1], 4.0, 1e-8);
  EXPECT_EQ(final.jacobian.rows(), 40);
  EXPECT_EQ(final.jacobian.cols(), 2);
  // r and R at the returned x: the function's own residuals, and RᵀR = JᵀJ.
  Eigen::VectorXd r_final;
  ASSERT_TRUE(problem.Residuals(x, r_final));
  EXPECT_LT((final.residuals - r_final).cwiseAbs().maxCoeff(), 1e-15);
  const Eigen::MatrixXd jtj = final.jacobian.transpose() * final.jacobian;
  EXPECT_LT((final.r_factor.transpose() * final.r_factor - jtj).cwiseAbs().maxCoeff(),
            1e-12 * jtj.cwiseAbs().maxCoeff());
}

// Marquardt's scaling: the same problem with one parameter a million times larger converges the
// same way.
TEST(LevenbergMarquardt, BadlyScaledParametersConverge) {
  const ExpDecay problem(3.0e6, 0.5);
  Eigen::VectorXd x(2);
  x << 1.0e6, 2.0;
  const SolverSummary s = LevenbergMarquardt(problem.Analytic(), x, SolverOptions{});
  ASSERT_TRUE(s.Converged()) << s.message;
  EXPECT_NEAR(x[0] / 3.0e6, 1.0, 1e-9);
  EXPECT_NEAR(x[1], 0.5, 1e-9);
}

// A step out of the domain counts as rejected: the search stays inside it.
TEST(LevenbergMarquardt, RejectedDomainKeepsTheSearchInside) {
  const ExpDecay problem(1.0, 0.05);
  Eigen::VectorXd x(2);
  x << 1.0, 3.0;
  const SolverSummary s =
      LevenbergMarquardt(NumericDiff([&](const Eigen::VectorXd& p, Eigen::VectorXd& r) {
                           if (p[1] < 0.0) return false;
                           return problem.Residuals(p, r);
                         }),
                         x, SolverOptions{});
  ASSERT_TRUE(s.Converged()) << s.message;
  EXPECT_GE(x[1], 0.0);
  EXPECT_NEAR(x[1], 0.05, 1e-8);
}

TEST(LevenbergMarquardt, NonFiniteStartIsANumericalFailure) {
  Eigen::VectorXd x = Eigen::VectorXd::Ones(1);
  const SolverSummary s =
      LevenbergMarquardt(NumericDiff([](const Eigen::VectorXd&, Eigen::VectorXd& r) {
                           r = Eigen::VectorXd::Constant(3, std::nan(""));
                           return true;
                         }),
                         x, SolverOptions{});
  EXPECT_EQ(s.termination, TerminationType::kNumericalFailure);
  EXPECT_FALSE(s.Converged());
  EXPECT_FALSE(s.message.empty());
}

TEST(LevenbergMarquardt, MaxIterationsKeepsTheBestPoint) {
  const ExpDecay problem(2.0, 3.0);
  Eigen::VectorXd x(2);
  x << 0.1, 0.1;
  SolverOptions options;
  options.max_iterations = 1;
  Eigen::VectorXd r0;
  problem.Residuals(x, r0);
  const ResidualFunction f = NumericDiff(
      [&](const Eigen::VectorXd& p, Eigen::VectorXd& r) { return problem.Residuals(p, r); });
  const SolverSummary s = LevenbergMarquardt(f, x, options);
  EXPECT_EQ(s.termination, TerminationType::kMaxIterations);
  EXPECT_EQ(s.iterations, 1);
  EXPECT_LT(s.final_cost, 0.5 * r0.squaredNorm());
}

TEST(SolverOptions, ValidatedBeforeAnyWork) {
  int calls = 0;
  const ResidualFunction counting = [&](const Eigen::VectorXd&, Eigen::VectorXd& r,
                                        Eigen::MatrixXd*) {
    ++calls;
    r = Eigen::VectorXd::Zero(1);
    return true;
  };
  Eigen::VectorXd x = Eigen::VectorXd::Zero(1);
  const auto expect_rejected = [&](SolverOptions o, const std::string& field) {
    try {
      LevenbergMarquardt(counting, x, o);
      ADD_FAILURE() << "accepted bad " << field;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  expect_rejected(SolverOptions{.max_iterations = 0}, "max_iterations");
  expect_rejected(SolverOptions{.function_tolerance = -1.0}, "function_tolerance");
  expect_rejected(SolverOptions{.parameter_tolerance = std::nan("")}, "parameter_tolerance");
  expect_rejected(SolverOptions{.gradient_tolerance = -1e-3}, "gradient_tolerance");
  expect_rejected(SolverOptions{.initial_damping = 0.0}, "initial_damping");
  EXPECT_EQ(calls, 0);
  const ResidualOnlyFunction any = [](const Eigen::VectorXd&, Eigen::VectorXd&) { return true; };
  EXPECT_THROW(NumericDiff(any, 0.0), InputError);
}

TEST(TerminationName, OneSpellingPerType) {
  EXPECT_STREQ(TerminationName(TerminationType::kFunctionTolerance), "function_tolerance");
  EXPECT_STREQ(TerminationName(TerminationType::kParameterTolerance), "parameter_tolerance");
  EXPECT_STREQ(TerminationName(TerminationType::kGradientTolerance), "gradient_tolerance");
  EXPECT_STREQ(TerminationName(TerminationType::kMaxIterations), "max_iterations");
  EXPECT_STREQ(TerminationName(TerminationType::kNumericalFailure), "numerical_failure");
}

TEST(CovarianceFromJacobian, MatchesTheNormalEquationsAndFlagsLostDirections) {
  Eigen::MatrixXd j(4, 2);
  j << 1.0, 0.0, 1.0, 1.0, 1.0, 2.0, 1.0, 3.0;
  Eigen::VectorXd r(4);
  r << 0.1, -0.2, 0.05, 0.1;
  const Eigen::MatrixXd cov = CovarianceFromJacobian(j, r);
  const Eigen::MatrixXd expected = r.squaredNorm() / 2.0 * (j.transpose() * j).inverse();
  EXPECT_LT((cov - expected).cwiseAbs().maxCoeff(), 1e-14);

  Eigen::MatrixXd rank_one(3, 2);
  rank_one << 1.0, 2.0, 2.0, 4.0, 3.0, 6.0;
  const Eigen::MatrixXd lost = CovarianceFromJacobian(rank_one, Eigen::Vector3d(0.1, 0.1, 0.1));
  EXPECT_TRUE(std::isinf(lost(0, 0)));
  EXPECT_TRUE(std::isinf(lost(1, 1)));
}

}  // namespace
}  // namespace vibid::numerics
