#include "backend/optimization/normal_equations.h"

#include <ceres/loss_function.h>
#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <vector>

#include "backend/optimization/least_squares_problem.h"
#include "core/image_pyramid.h"
#include "residuals/photometric_residual.h"
#include "residuals/point_to_line_residual.h"
#include "residuals/se3_manifold.h"
#include "tests/residuals/residual_test_utils.h"

namespace pldvo {
namespace {

using testing_utils::PlaceReferencePixel;
using testing_utils::TestCamera;
using testing_utils::TestCurFromRef;

// Forwards Evaluate() only: hides PoseTangentCostFunction, so NormalEquations takes the generic
// path (ambient Jacobian times PlusJacobian).
class AmbientOnly : public ceres::CostFunction {
 public:
  explicit AmbientOnly(const ceres::CostFunction& wrapped) : wrapped_(wrapped) {
    set_num_residuals(wrapped.num_residuals());
    *mutable_parameter_block_sizes() = wrapped.parameter_block_sizes();
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    return wrapped_.Evaluate(parameters, residuals, jacobians);
  }

 private:
  const ceres::CostFunction& wrapped_;
};

struct Rows {
  std::vector<PhotometricObservation> photometric;
  std::vector<PointToLineObservation> lines;
};

// Reference pixels spread over the image at random depths, a few of them reprojecting outside
// (invalid rows), and line observations whose lines miss the reprojections by up to 2 px.
Rows MakeRows(const PinholeCamera& camera, const SE3& cur_from_ref) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-10.0, camera.width + 10.0);
  std::uniform_real_distribution<double> v(-10.0, camera.height + 10.0);
  std::uniform_real_distribution<double> depth(1.0, 4.0);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Rows rows;
  for (int i = 0; i < 300; ++i) {
    PhotometricObservation o;
    PlaceReferencePixel(camera, cur_from_ref, {u(rng), v(rng)}, depth(rng), &o.pixel_in_ref,
                        &o.idepth);
    o.intensity_ref =
        testing_utils::SmoothIntensity(o.pixel_in_ref.x(), o.pixel_in_ref.y()) + 20.0 * unit(rng);
    o.sqrt_info = 0.2 + 0.1 * unit(rng);
    rows.photometric.push_back(o);
    PointToLineObservation l;
    l.pixel_in_ref = o.pixel_in_ref;
    l.idepth = o.idepth;
    const double angle = 3.0 * unit(rng);
    const Eigen::Vector2d normal(std::cos(angle), std::sin(angle));
    const Eigen::Vector2d x = camera.Project(cur_from_ref * camera.Unproject(o.pixel_in_ref));
    l.line_in_cur << normal, -normal.dot(x) + 2.0 * unit(rng);
    l.sqrt_info = 1.5 + unit(rng);
    rows.lines.push_back(l);
  }
  return rows;
}

struct Linearization {
  Eigen::MatrixXd hessian;
  Eigen::VectorXd gradient;
  double cost = 0.0;
  int pose_tangent_blocks = 0;
};

struct RowsSetup {
  BrightnessModel brightness = BrightnessModel::kNone;
  bool brightness_variable = false;
  bool block_loss = false;  // a LossFunction on each residual block (Triggs correction)
};

// H, g and the cost of photometric and point-to-line rows at a pose near the truth; with
// `hide_tangent` through Evaluate() only; `blocks`: only those residual blocks (0 photometric,
// 1 point-to-line; nullptr: both).
Linearization LinearizeRows(const RowsSetup& setup, bool hide_tangent,
                            const std::vector<int>* blocks = nullptr) {
  const PinholeCamera camera = TestCamera();
  const SE3 truth = TestCurFromRef();
  const ImagePyramid pyramid(testing_utils::SampleImage(camera, testing_utils::SmoothIntensity), 1);
  const Rows rows = MakeRows(camera, truth);
  Vector6d perturbation;
  perturbation << 0.01, -0.02, 0.015, 0.004, 0.003, -0.005;
  double pose[kPoseAmbientSize];
  PoseToParameters(SE3::Exp(perturbation) * truth, pose);
  double ab[2] = {0.05, -3.0};
  const ceres::HuberLoss row_loss(1.0);
  auto photometric =
      std::make_unique<PhotometricResidual>(pyramid, 0, camera, rows.photometric, &row_loss,
                                            ImageInterpolation::kBilinear, setup.brightness);
  auto lines = std::make_unique<PointToLineResidual>(camera, rows.lines, &row_loss);

  LeastSquaresProblem problem;
  problem.AddParameterBlock(pose, kPoseAmbientSize, std::make_unique<SE3Manifold>());
  std::vector<double*> photometric_blocks = {pose};
  if (setup.brightness == BrightnessModel::kAffine) {
    problem.AddParameterBlock(ab, 2);
    if (!setup.brightness_variable) problem.SetParameterBlockConstant(ab);
    photometric_blocks.push_back(ab);
  }
  ceres::LossFunction* loss =
      setup.block_loss ? problem.AddLossFunction(std::make_unique<ceres::CauchyLoss>(30.0))
                       : nullptr;
  if (hide_tangent) {
    problem.AddResidualBlock(std::make_unique<AmbientOnly>(*photometric), loss, photometric_blocks);
    problem.AddResidualBlock(std::make_unique<AmbientOnly>(*lines), loss, {pose});
  } else {
    problem.AddResidualBlock(std::move(photometric), loss, photometric_blocks);
    problem.AddResidualBlock(std::move(lines), loss, {pose});
  }
  NormalEquations equations(problem);
  Linearization result;
  EXPECT_TRUE(equations.LinearizeBlocks(blocks, &result.cost));
  result.hessian = equations.hessian();
  result.gradient = equations.gradient();
  result.pose_tangent_blocks = equations.num_pose_tangent_blocks();
  return result;
}

void ExpectSameLinearization(const RowsSetup& setup, int pose_tangent_blocks) {
  const Linearization generic = LinearizeRows(setup, true);
  const Linearization tangent = LinearizeRows(setup, false);
  ASSERT_EQ(generic.pose_tangent_blocks, 0);
  ASSERT_EQ(tangent.pose_tangent_blocks, pose_tangent_blocks);
  ASSERT_GT(generic.hessian.norm(), 0.0);
  ASSERT_GT(generic.gradient.norm(), 0.0);
  // The cost is computed from the same residuals in the same order.
  EXPECT_EQ(tangent.cost, generic.cost);
  // J_tangent versus (J_tangent MinusJacobian) PlusJacobian: equal up to rounding.
  EXPECT_LE((tangent.hessian - generic.hessian).cwiseAbs().maxCoeff(),
            1e-12 * generic.hessian.cwiseAbs().maxCoeff());
  EXPECT_LE((tangent.gradient - generic.gradient).cwiseAbs().maxCoeff(),
            1e-12 * generic.gradient.cwiseAbs().maxCoeff());
}

// H, g and the cost are sums over the residual blocks: linearising a subset (as a
// marginalisation does) gives that subset's share.
TEST(NormalEquationsTest, SubsetsOfBlocksAddUpToTheWhole) {
  RowsSetup setup;
  setup.brightness = BrightnessModel::kAffine;
  setup.brightness_variable = true;
  setup.block_loss = true;
  const std::vector<int> photometric = {0}, lines = {1};
  const Linearization whole = LinearizeRows(setup, false);
  const Linearization a = LinearizeRows(setup, false, &photometric);
  const Linearization b = LinearizeRows(setup, false, &lines);
  ASSERT_GT(a.hessian.norm(), 0.0);
  ASSERT_GT(b.hessian.norm(), 0.0);
  EXPECT_LE((a.hessian + b.hessian - whole.hessian).cwiseAbs().maxCoeff(),
            1e-12 * whole.hessian.cwiseAbs().maxCoeff());
  EXPECT_LE((a.gradient + b.gradient - whole.gradient).cwiseAbs().maxCoeff(),
            1e-12 * whole.gradient.cwiseAbs().maxCoeff());
  EXPECT_NEAR(a.cost + b.cost, whole.cost, 1e-12 * whole.cost);
}

TEST(NormalEquationsTest, PoseTangentRowsGiveTheGenericHessianAndGradient) {
  ExpectSameLinearization({}, 2);
}

TEST(NormalEquationsTest, PoseTangentRowsKeepTheBlockLossCorrection) {
  RowsSetup setup;
  setup.block_loss = true;
  ExpectSameLinearization(setup, 2);
}

TEST(NormalEquationsTest, PoseTangentRowsApplyAConstantBrightness) {
  RowsSetup setup;
  setup.brightness = BrightnessModel::kAffine;
  ExpectSameLinearization(setup, 2);
}

TEST(NormalEquationsTest, VariableBrightnessRowsTakeTheGenericPath) {
  // The photometric block reads two variable blocks (generic path), the line block only the
  // pose (tangent rows): together they still give the generic H and g.
  RowsSetup setup;
  setup.brightness = BrightnessModel::kAffine;
  setup.brightness_variable = true;
  ASSERT_EQ(LinearizeRows(setup, false).hessian.rows(), 8);
  ExpectSameLinearization(setup, 1);
}

}  // namespace
}  // namespace pldvo
