// The two solvers on LeastSquaresProblem: same minimum on Euclidean, manifold and robust
// problems; the problem's conversion to ceres::Problem; input checks.
#include "backend/optimization/solver.h"

#include <ceres/ceres.h>
#include <ceres/normal_prior.h>
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "backend/optimization/ceres_solver.h"
#include "backend/optimization/gauss_newton_solver.h"
#include "backend/optimization/least_squares_problem.h"
#include "core/random_draws.h"
#include "residuals/se3_manifold.h"

namespace pldvo {
namespace {

// r = y - exp(m x + c), parameter block (m, c).
class ExponentialResidual : public ceres::SizedCostFunction<1, 2> {
 public:
  ExponentialResidual(double x, double y) : x_(x), y_(y) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double e = std::exp(parameters[0][0] * x_ + parameters[0][1]);
    residuals[0] = y_ - e;
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      jacobians[0][0] = -x_ * e;
      jacobians[0][1] = -e;
    }
    return true;
  }

 private:
  const double x_, y_;
};

// r = cur_from_ref * p_ref - p_cur (3 rows), with the analytic tangent Jacobian [I, -[p']x]
// lifted by the pose's MinusJacobian. A batch of points in one block.
class PointAlignmentResidual : public ceres::CostFunction {
 public:
  PointAlignmentResidual(std::vector<Eigen::Vector3d> points_in_ref,
                         std::vector<Eigen::Vector3d> points_in_cur)
      : points_in_ref_(std::move(points_in_ref)), points_in_cur_(std::move(points_in_cur)) {
    set_num_residuals(3 * static_cast<int>(points_in_ref_.size()));
    mutable_parameter_block_sizes()->push_back(kPoseAmbientSize);
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const SE3 cur_from_ref = PoseFromParameters(parameters[0]);
    const MinusJacobianMatrix minus = PoseMinusJacobian(parameters[0]);
    for (size_t i = 0; i < points_in_ref_.size(); ++i) {
      const Eigen::Vector3d p = cur_from_ref * points_in_ref_[i];
      Eigen::Map<Eigen::Vector3d>(residuals + 3 * i) = p - points_in_cur_[i];
      if (jacobians != nullptr && jacobians[0] != nullptr) {
        Eigen::Matrix<double, 3, 6, Eigen::RowMajor> tangent;
        tangent.leftCols<3>().setIdentity();
        tangent.rightCols<3>() = -Hat(p);
        LiftTangentJacobian(minus, tangent.data(), 3, jacobians[0] + 21 * i);
      }
    }
    return true;
  }

 private:
  std::vector<Eigen::Vector3d> points_in_ref_, points_in_cur_;
};

SolverOptions TightOptions(SolverOptions::Type type) {
  SolverOptions options;
  options.type = type;
  options.max_iterations = 100;
  options.function_tolerance = 1e-15;
  options.gradient_tolerance = 1e-14;
  options.parameter_tolerance = 1e-14;
  return options;
}

TEST(SolverTest, EuclideanCurveFitSameMinimum) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.05);
  std::vector<std::pair<double, double>> data;
  for (int i = 0; i < 40; ++i) {
    const double x = i / 40.0;
    data.emplace_back(x, std::exp(0.3 * x + 0.1) + noise(rng));
  }
  double results[2][2];
  for (int s = 0; s < 2; ++s) {
    double* mc = results[s];
    mc[0] = 0.0;
    mc[1] = 0.0;
    LeastSquaresProblem problem;
    problem.AddParameterBlock(mc, 2);
    for (const auto& [x, y] : data) {
      problem.AddResidualBlock(std::make_unique<ExponentialResidual>(x, y), nullptr, {mc});
    }
    const auto solver = MakeSolver(
        TightOptions(s == 0 ? SolverOptions::Type::kCeres : SolverOptions::Type::kGaussNewton));
    const SolverSummary summary = solver->Solve(&problem);
    EXPECT_TRUE(summary.converged) << summary.message;
    EXPECT_LT(summary.final_cost, summary.initial_cost);
  }
  // Both stop where the cost no longer changes in double precision: |dx| ~ sqrt(2 eps cost / h)
  // ~ 1e-9 for cost ~ 0.05 and curvature h ~ 10, so 1e-7 bounds the agreement with margin while
  // staying far below the noise-induced parameter spread (~1e-2).
  EXPECT_NEAR(results[0][0], results[1][0], 1e-7);
  EXPECT_NEAR(results[0][1], results[1][1], 1e-7);
}

struct PoseProblemData {
  std::vector<Eigen::Vector3d> points_in_ref, points_in_cur;
  SE3 cur_from_ref;
};

PoseProblemData MakePoseData(int num_points, int num_outliers, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.01);
  PoseProblemData data;
  Vector6d twist;
  twist << 0.3, -0.2, 0.1, 0.2, -0.3, 0.25;
  data.cur_from_ref = SE3::Exp(twist);
  for (int i = 0; i < num_points; ++i) {
    const Eigen::Vector3d r = DrawVector3(uniform, rng);
    const Eigen::Vector3d p(r.x(), r.y(), 3.0 + r.z());
    data.points_in_ref.push_back(p);
    Eigen::Vector3d q = data.cur_from_ref * p + DrawVector3(noise, rng);
    if (i < num_outliers) q += DrawVector3(uniform, rng);
    data.points_in_cur.push_back(q);
  }
  return data;
}

// Solves the point alignment with one solver; batch 0 means one block per point with `loss` as
// a ceres::LossFunction on each block.
SE3 SolvePose(const PoseProblemData& data, SolverOptions::Type type, bool per_point_loss,
              SolverSummary* summary, double* cost_at_step4 = nullptr) {
  double pose[7];
  PoseToParameters(SE3(), pose);
  LeastSquaresProblem problem;
  problem.AddParameterBlock(pose, 7, std::make_unique<SE3Manifold>());
  if (per_point_loss) {
    ceres::LossFunction* loss = problem.AddLossFunction(std::make_unique<ceres::CauchyLoss>(0.05));
    for (size_t i = 0; i < data.points_in_ref.size(); ++i) {
      problem.AddResidualBlock(std::make_unique<PointAlignmentResidual>(
                                   std::vector<Eigen::Vector3d>{data.points_in_ref[i]},
                                   std::vector<Eigen::Vector3d>{data.points_in_cur[i]}),
                               loss, {pose});
    }
  } else {
    problem.AddResidualBlock(
        std::make_unique<PointAlignmentResidual>(data.points_in_ref, data.points_in_cur), nullptr,
        {pose});
  }
  *summary = MakeSolver(TightOptions(type))->Solve(&problem, [&](const SolverIteration& it) {
    if (cost_at_step4 != nullptr && it.iteration == 4) *cost_at_step4 = it.cost;
  });
  return PoseFromParameters(pose);
}

TEST(SolverTest, PoseOnManifoldSameMinimum) {
  const PoseProblemData data = MakePoseData(50, 0, 3);
  SolverSummary ceres_summary, gn_summary;
  const SE3 ceres_pose = SolvePose(data, SolverOptions::Type::kCeres, false, &ceres_summary);
  double gn_at_step4 = 0.0;
  const SE3 gn_pose =
      SolvePose(data, SolverOptions::Type::kGaussNewton, false, &gn_summary, &gn_at_step4);
  EXPECT_TRUE(ceres_summary.converged) << ceres_summary.message;
  EXPECT_TRUE(gn_summary.converged) << gn_summary.message;
  const Vector6d difference = (ceres_pose * gn_pose.Inverse()).Log();
  // Both converge to the unique minimum; stopping at a relative cost change of 1e-15 leaves
  // |dx| ~ sqrt(2e-15 cost / h) ~ 1e-9 (cost ~ 8e-3, curvature h ~ 10), hence 1e-8.
  EXPECT_LT(difference.norm(), 1e-8);
  // And that minimum is the truth up to the 1 cm point noise.
  EXPECT_LT((gn_pose * data.cur_from_ref.Inverse()).Log().norm(), 0.01);
  // Gauss-Newton converges quadratically from 0.5 rad away: the cost is within 1e-6 of its
  // final value after 4 steps (later iterations only hit the 1e-15 tolerances of this test).
  EXPECT_LE(gn_summary.accepted_iterations, gn_summary.iterations);
  EXPECT_LT(gn_at_step4 - gn_summary.final_cost, 1e-6 * gn_summary.final_cost);
  EXPECT_NEAR(ceres_summary.final_cost, gn_summary.final_cost, 1e-12);
}

TEST(SolverTest, LossFunctionBlocksSameMinimumWithTriggsCorrection) {
  // 30% gross outliers, Cauchy loss per point block: Ceres applies its corrector, our
  // Gauss-Newton the same Triggs correction; they must find the same robust minimum.
  const PoseProblemData data = MakePoseData(60, 18, 5);
  SolverSummary ceres_summary, gn_summary;
  const SE3 ceres_pose = SolvePose(data, SolverOptions::Type::kCeres, true, &ceres_summary);
  const SE3 gn_pose = SolvePose(data, SolverOptions::Type::kGaussNewton, true, &gn_summary);
  EXPECT_TRUE(ceres_summary.converged) << ceres_summary.message;
  EXPECT_TRUE(gn_summary.converged) << gn_summary.message;
  EXPECT_LT((ceres_pose * gn_pose.Inverse()).Log().norm(), 1e-8);
  EXPECT_NEAR(ceres_summary.final_cost, gn_summary.final_cost, 1e-10);
  // The robust estimate stays near the truth despite the outliers (noise 1 cm).
  EXPECT_LT((gn_pose * data.cur_from_ref.Inverse()).Log().norm(), 0.02);
}

TEST(SolverTest, GaussNewtonCostNeverIncreasesAndCallbackSeesEveryIteration) {
  const PoseProblemData data = MakePoseData(40, 10, 11);
  double pose[7];
  PoseToParameters(SE3(), pose);
  LeastSquaresProblem problem;
  problem.AddParameterBlock(pose, 7, std::make_unique<SE3Manifold>());
  ceres::LossFunction* loss = problem.AddLossFunction(std::make_unique<ceres::HuberLoss>(0.02));
  for (size_t i = 0; i < data.points_in_ref.size(); ++i) {
    problem.AddResidualBlock(std::make_unique<PointAlignmentResidual>(
                                 std::vector<Eigen::Vector3d>{data.points_in_ref[i]},
                                 std::vector<Eigen::Vector3d>{data.points_in_cur[i]}),
                             loss, {pose});
  }
  std::vector<SolverIteration> iterations;
  const SolverSummary summary =
      GaussNewtonSolver(TightOptions(SolverOptions::Type::kGaussNewton))
          .Solve(&problem, [&](const SolverIteration& it) { iterations.push_back(it); });
  ASSERT_FALSE(iterations.empty());
  EXPECT_EQ(iterations.front().iteration, 0);
  EXPECT_EQ(static_cast<int>(iterations.size()), summary.iterations + 1);
  for (size_t i = 1; i < iterations.size(); ++i) {
    EXPECT_LE(iterations[i].cost, iterations[i - 1].cost);
  }
  double cost = 0.0;
  ASSERT_TRUE(problem.EvaluateCost(&cost));
  EXPECT_DOUBLE_EQ(cost, summary.final_cost);
}

// ExponentialResidual that counts its evaluations with and without Jacobians.
class CountingExponentialResidual : public ExponentialResidual {
 public:
  CountingExponentialResidual(double x, double y, int* with_jacobians, int* cost_only)
      : ExponentialResidual(x, y), with_jacobians_(with_jacobians), cost_only_(cost_only) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    ++*(jacobians != nullptr ? with_jacobians_ : cost_only_);
    return ExponentialResidual::Evaluate(parameters, residuals, jacobians);
  }

 private:
  int* with_jacobians_;
  int* cost_only_;
};

TEST(SolverTest, GaussNewtonLinearisesATrialAfterAnAcceptedStepOnce) {
  // Start far from the minimum so that the solve has a run of accepted steps and rejections.
  double mc[2] = {3.0, -2.0};
  int with_jacobians = 0;
  int cost_only = 0;
  LeastSquaresProblem problem;
  problem.AddParameterBlock(mc, 2);
  constexpr int kBlocks = 20;
  for (int i = 0; i < kBlocks; ++i) {
    const double x = i / static_cast<double>(kBlocks);
    problem.AddResidualBlock(
        std::make_unique<CountingExponentialResidual>(
            x, std::exp(0.3 * x + 0.1) + 0.01 * std::sin(7.0 * i), &with_jacobians, &cost_only),
        nullptr, {mc});
  }
  std::vector<bool> accepted;
  const SolverSummary summary = GaussNewtonSolver(TightOptions(SolverOptions::Type::kGaussNewton))
                                    .Solve(&problem, [&](const SolverIteration& it) {
                                      if (it.iteration > 0) accepted.push_back(it.step_accepted);
                                    });
  ASSERT_TRUE(summary.converged) << summary.message;
  // The rule: the initial point and every trial after an accepted step (or the start) are
  // linearised; a trial after a rejection is only costed, and linearised once if accepted.
  int expected_jacobians = 1;
  int expected_cost_only = 0;
  int num_accepted = 0;
  bool after_acceptance = true;
  for (const bool a : accepted) {
    if (after_acceptance) {
      ++expected_jacobians;
    } else {
      ++expected_cost_only;
      if (a) ++expected_jacobians;
    }
    after_acceptance = a;
    num_accepted += a;
  }
  ASSERT_GE(num_accepted, 3);
  EXPECT_EQ(with_jacobians, kBlocks * expected_jacobians);
  EXPECT_EQ(cost_only, kBlocks * expected_cost_only);
  // Fewer evaluations than costing every trial and relinearising every accepted one.
  const int separate = kBlocks * (1 + num_accepted + static_cast<int>(accepted.size()));
  EXPECT_LT(with_jacobians + cost_only, separate);
}

TEST(SolverTest, ConstantBlockIsNotMoved) {
  double mc[2] = {0.1, 0.2};
  LeastSquaresProblem problem;
  problem.AddParameterBlock(mc, 2);
  problem.AddResidualBlock(std::make_unique<ExponentialResidual>(0.5, 3.0), nullptr, {mc});
  problem.SetParameterBlockConstant(mc);
  for (auto type : {SolverOptions::Type::kCeres, SolverOptions::Type::kGaussNewton}) {
    MakeSolver(TightOptions(type))->Solve(&problem);
    EXPECT_EQ(mc[0], 0.1);
    EXPECT_EQ(mc[1], 0.2);
  }
}

TEST(LeastSquaresProblemTest, RejectsBadInput) {
  double x[2] = {0, 0};
  double y[3] = {0, 0, 0};
  LeastSquaresProblem problem;
  problem.AddParameterBlock(x, 2);
  EXPECT_THROW(problem.AddParameterBlock(x, 2), std::invalid_argument);
  EXPECT_THROW(problem.AddParameterBlock(y, 3, std::make_unique<SE3Manifold>()),
               std::invalid_argument);
  // Not added / wrong size.
  EXPECT_THROW(problem.AddResidualBlock(std::make_unique<ExponentialResidual>(0, 0), nullptr, {y}),
               std::invalid_argument);
  EXPECT_THROW(
      problem.AddResidualBlock(std::make_unique<ExponentialResidual>(0, 0), nullptr, {x, x}),
      std::invalid_argument);
  SolverOptions bad;
  bad.num_threads = 0;
  EXPECT_THROW(MakeSolver(bad), std::invalid_argument);
}

TEST(LeastSquaresProblemTest, CeresProblemSharesBlocksAndCost) {
  double mc[2] = {0.2, -0.1};
  LeastSquaresProblem problem;
  problem.AddParameterBlock(mc, 2);
  ceres::LossFunction* loss = problem.AddLossFunction(std::make_unique<ceres::HuberLoss>(0.1));
  for (int i = 0; i < 5; ++i) {
    problem.AddResidualBlock(std::make_unique<ExponentialResidual>(i * 0.1, 1.0 + i), loss, {mc});
  }
  double cost = 0.0;
  ASSERT_TRUE(problem.EvaluateCost(&cost));
  {
    const std::unique_ptr<ceres::Problem> ceres_problem = problem.ToCeresProblem();
    double ceres_cost = 0.0;
    ASSERT_TRUE(ceres_problem->Evaluate(ceres::Problem::EvaluateOptions(), &ceres_cost, nullptr,
                                        nullptr, nullptr));
    EXPECT_DOUBLE_EQ(cost, ceres_cost);
    EXPECT_EQ(ceres_problem->NumResidualBlocks(), 5);
  }  // the ceres::Problem does not own, so our problem stays usable:
  ASSERT_TRUE(problem.EvaluateCost(&cost));
  EXPECT_EQ(problem.NumResiduals(), 5);
}

}  // namespace
}  // namespace pldvo

namespace pldvo {
namespace {

// r_ij = exp(a x_i) + b x_i^2 - y_ij over per-point scalars x_i (1-D blocks, marked
// eliminated) and a shared {a, b}, plus a prior on each x_i: the structure of bundle adjustment
// (inverse depths and camera parameters).
class SharedCurveResidual : public ceres::SizedCostFunction<1, 1, 2> {
 public:
  explicit SharedCurveResidual(double y) : y_(y) {}
  bool Evaluate(double const* const* p, double* r, double** j) const override {
    const double x = p[0][0], a = p[1][0], b = p[1][1];
    const double e = std::exp(a * x);
    r[0] = e + b * x * x - y_;
    if (j != nullptr && j[0] != nullptr) j[0][0] = a * e + 2.0 * b * x;
    if (j != nullptr && j[1] != nullptr) {
      j[1][0] = x * e;
      j[1][1] = x * x;
    }
    return true;
  }

 private:
  double y_;
};

// The Schur-complement step of marked 1-D blocks is the dense step to rounding: Gauss-Newton
// with and without the marks takes the same steps and ends at the same parameters (1e-9, far
// above rounding and far below the 1e-2 moves of the solve). Breaking it: a wrong sign in
// the back-substitution of delta_P, or damping left off S's diagonal, makes the two runs part
// after the first step.
TEST(SolverTest, SchurEliminationTakesTheDenseSteps) {
  auto solve = [](bool eliminate, std::vector<double>* x, std::array<double, 2>* shared) {
    std::mt19937 rng(5);
    std::normal_distribution<double> noise(0.0, 0.01);
    constexpr int kPoints = 30;
    x->assign(kPoints, 0.0);
    *shared = {0.1, 0.1};
    LeastSquaresProblem problem;
    problem.AddParameterBlock(shared->data(), 2);
    for (int i = 0; i < kPoints; ++i) {
      const double x_true = -1.0 + 2.0 * i / (kPoints - 1);
      (*x)[i] = x_true + 0.05;
      problem.AddParameterBlock(&(*x)[i], 1);
      if (eliminate) problem.SetParameterBlockEliminated(&(*x)[i]);
      for (int k = 0; k < 3; ++k) {
        const double y = std::exp(0.5 * x_true) + 0.3 * x_true * x_true + noise(rng);
        problem.AddResidualBlock(std::make_unique<SharedCurveResidual>(y), nullptr,
                                 {&(*x)[i], shared->data()});
      }
      problem.AddResidualBlock(
          std::make_unique<ceres::NormalPrior>(Eigen::Matrix<double, 1, 1>::Constant(10.0),
                                               Eigen::Matrix<double, 1, 1>::Constant(x_true)),
          nullptr, {&(*x)[i]});
    }
    SolverOptions options;
    options.initial_lambda = 1e-3;
    options.function_tolerance = 1e-12;
    return GaussNewtonSolver(options).Solve(&problem);
  };
  std::vector<double> x_dense, x_schur;
  std::array<double, 2> shared_dense, shared_schur;
  const SolverSummary dense = solve(false, &x_dense, &shared_dense);
  const SolverSummary schur = solve(true, &x_schur, &shared_schur);
  EXPECT_EQ(dense.iterations, schur.iterations);
  EXPECT_GT(schur.accepted_iterations, 1);
  EXPECT_LT(schur.final_cost, 0.1 * schur.initial_cost);
  EXPECT_NEAR(schur.final_cost, dense.final_cost, 1e-9 * dense.final_cost);
  EXPECT_NEAR(shared_schur[0], shared_dense[0], 1e-9);
  EXPECT_NEAR(shared_schur[1], shared_dense[1], 1e-9);
  for (size_t i = 0; i < x_dense.size(); ++i) EXPECT_NEAR(x_schur[i], x_dense[i], 1e-9);
}

}  // namespace
}  // namespace pldvo
