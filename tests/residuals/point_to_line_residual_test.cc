#include "residuals/point_to_line_residual.h"

#include <ceres/autodiff_cost_function.h>
#include <ceres/gradient_checker.h>
#include <ceres/loss_function.h>
#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <stdexcept>

#include "residuals/se3_manifold.h"
#include "tests/residuals/residual_test_utils.h"

namespace pldvo {
namespace {

using testing_utils::CompareWithTwin;
using testing_utils::PlaceReferencePixel;
using testing_utils::TestCamera;
using testing_utils::TestCurFromRef;
using testing_utils::TwinComparison;

enum class Loss { kNone, kHuber, kCauchy };
constexpr double kLossScale = 1.0;

std::unique_ptr<ceres::LossFunction> MakeLoss(Loss loss) {
  if (loss == Loss::kHuber) return std::make_unique<ceres::HuberLoss>(kLossScale);
  if (loss == Loss::kCauchy) return std::make_unique<ceres::CauchyLoss>(kLossScale);
  return nullptr;
}

struct PointToLineTwin {
  PointToLineTwin(const PinholeCamera& camera,
                  const std::vector<PointToLineObservation>& observations, Loss loss)
      : camera(camera), observations(observations), loss(loss) {}

  template <typename T>
  bool operator()(const T* pose, T* residuals) const {
    Eigen::Quaternion<T> rotation(pose[6], pose[3], pose[4], pose[5]);
    rotation.normalize();
    const Eigen::Matrix<T, 3, 1> translation(pose[0], pose[1], pose[2]);
    for (size_t i = 0; i < observations.size(); ++i) {
      const PointToLineObservation& o = observations[i];
      const Eigen::Matrix<T, 3, 1> point_in_cur =
          rotation * (camera.Unproject(o.pixel_in_ref) / o.idepth).cast<T>() + translation;
      const T u = T(camera.fx) * point_in_cur.x() / point_in_cur.z() + T(camera.cx);
      const T v = T(camera.fy) * point_in_cur.y() / point_in_cur.z() + T(camera.cy);
      const T g = T(o.sqrt_info) *
                  (T(o.line_in_cur.x()) * u + T(o.line_in_cur.y()) * v + T(o.line_in_cur.z()));
      if (loss == Loss::kHuber) {
        residuals[i] = testing_utils::HuberSqrtForm(g, kLossScale);
      } else if (loss == Loss::kCauchy) {
        residuals[i] = testing_utils::CauchySqrtForm(g, kLossScale);
      } else {
        residuals[i] = g;
      }
    }
    return true;
  }

  const PinholeCamera camera;
  const std::vector<PointToLineObservation> observations;
  const Loss loss;
};

class PointToLineResidualTest : public ::testing::Test {
 protected:
  PointToLineResidualTest() : camera_(TestCamera()), cur_from_ref_(TestCurFromRef()) {
    PoseToParameters(cur_from_ref_, pose_);
  }

  // Edge pixels reprojecting into the image, each matched to a random line passing near its
  // reprojection (whitened distances in both zones of the robust losses).
  std::vector<PointToLineObservation> MakeObservations(int count, unsigned seed) const {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u_dist(5.0, camera_.width - 6.0);
    std::uniform_real_distribution<double> v_dist(5.0, camera_.height - 6.0);
    std::uniform_real_distribution<double> depth_dist(1.5, 5.0);
    std::uniform_real_distribution<double> angle_dist(0.0, 6.283185307179586);
    std::uniform_real_distribution<double> inlier_dist(0.2, 0.8);
    std::uniform_real_distribution<double> outlier_dist(1.3, 3.0);
    std::uniform_real_distribution<double> sqrt_info_dist(0.6, 1.0);
    std::vector<PointToLineObservation> observations;
    for (int i = 0; i < count; ++i) {
      const double v = v_dist(rng), u = u_dist(rng);  // core/random_draws.h
      const Eigen::Vector2d pixel_in_cur(u, v);
      PointToLineObservation o;
      PlaceReferencePixel(camera_, cur_from_ref_, pixel_in_cur, depth_dist(rng), &o.pixel_in_ref,
                          &o.idepth);
      const double angle = angle_dist(rng);
      const Eigen::Vector2d normal(std::cos(angle), std::sin(angle));
      // Whitened distance +-(0.2 .. 0.8) or +-(1.3 .. 3.0): away from the Huber kink at 1,
      // where the robustified row is only C1 and numeric differences would straddle it.
      const double whitened =
          (i % 2 == 0 ? 1.0 : -1.0) * (i % 4 < 2 ? inlier_dist(rng) : outlier_dist(rng));
      o.sqrt_info = sqrt_info_dist(rng);
      o.line_in_cur << normal, whitened / o.sqrt_info - normal.dot(pixel_in_cur);
      observations.push_back(o);
    }
    return observations;
  }

  // GradientChecker with the SE3Manifold, no loss, Huber and Cauchy, Ridders from a 1e-5
  // relative step. The residual is a smooth double-precision function, so Ridders is accurate to
  // ~1e-9; tolerance 1e-6 (the per-entry relative test also meets entries that nearly cancel).
  void ExpectGradientCheckerPasses(const std::vector<PointToLineObservation>& observations,
                                   const SharedLineError& shared) const {
    const SE3Manifold manifold;
    const std::vector<const ceres::Manifold*> manifolds = {&manifold};
    ceres::NumericDiffOptions options;
    options.ridders_relative_initial_step_size = 1e-5;
    for (const Loss loss_kind : {Loss::kNone, Loss::kHuber, Loss::kCauchy}) {
      const auto loss = MakeLoss(loss_kind);
      const PointToLineResidual cost(camera_, observations, loss.get(), shared);
      const ceres::GradientChecker checker(&cost, &manifolds, options);
      ceres::GradientChecker::ProbeResults results;
      const double* parameters[] = {pose_};
      EXPECT_TRUE(checker.Probe(parameters, 1e-6, &results)) << results.error_log;
    }
  }

  PinholeCamera camera_;
  SE3 cur_from_ref_;
  double pose_[7];
};

// Analytic == autodiff (all in double, no interpolation): to rounding, 1e-10 of the largest
// entry.
TEST_F(PointToLineResidualTest, AnalyticMatchesAutoDiff) {
  for (const Loss loss_kind : {Loss::kNone, Loss::kHuber, Loss::kCauchy}) {
    const auto loss = MakeLoss(loss_kind);
    const auto observations = MakeObservations(40, 1);
    const int n = static_cast<int>(observations.size());
    const PointToLineResidual analytic(camera_, observations, loss.get());
    ceres::AutoDiffCostFunction<PointToLineTwin, ceres::DYNAMIC, 7> twin(
        new PointToLineTwin(camera_, observations, loss_kind), n);
    const TwinComparison c = CompareWithTwin(analytic, twin, pose_, n);
    ASSERT_TRUE(c.evaluated);
    EXPECT_EQ(analytic.num_valid(), n);
    EXPECT_LT(c.max_residual_difference, 1e-10);
    EXPECT_LT(c.max_tangent_difference, 1e-10 * c.tangent_scale);
  }
}

TEST_F(PointToLineResidualTest, GradientChecker) {
  ExpectGradientCheckerPasses(MakeObservations(30, 2), SharedLineError());
}

// The residual is the signed pixel distance to the line, times sqrt_info.
TEST_F(PointToLineResidualTest, ResidualIsWhitenedSignedDistance) {
  PointToLineObservation o;
  PlaceReferencePixel(camera_, cur_from_ref_, Eigen::Vector2d(60.0, 40.0), 3.0, &o.pixel_in_ref,
                      &o.idepth);
  o.line_in_cur = Eigen::Vector3d(0.6, 0.8, -(0.6 * 60.0 + 0.8 * 40.0) - 2.5);  // 2.5 px away
  o.sqrt_info = 0.5;
  const PointToLineResidual cost(camera_, {o});
  double residual;
  cost.EvaluateTangent(cur_from_ref_, &residual, nullptr, nullptr);
  EXPECT_NEAR(residual, 0.5 * -2.5, 1e-9);
}

TEST_F(PointToLineResidualTest, InvalidRowsAreZeroAndFlagged) {
  // The current camera moved 1 m forward, so reference points nearer than 1 m are behind it.
  const SE3 cur_from_ref(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.05, -0.02, -1.0));
  double pose[7];
  PoseToParameters(cur_from_ref, pose);
  std::vector<PointToLineObservation> observations(3);
  for (auto& o : observations) o.line_in_cur = Eigen::Vector3d(0.6, 0.8, -70.0);
  // Row 0: valid. Row 1: below the image. Row 2: behind the current camera.
  PlaceReferencePixel(camera_, cur_from_ref, Eigen::Vector2d(60.0, 50.0), 3.0,
                      &observations[0].pixel_in_ref, &observations[0].idepth);
  PlaceReferencePixel(camera_, cur_from_ref, Eigen::Vector2d(80.0, camera_.height + 5.0), 3.0,
                      &observations[1].pixel_in_ref, &observations[1].idepth);
  observations[2].pixel_in_ref = Eigen::Vector2d(80.0, 60.0);
  observations[2].idepth = 2.0;
  const PointToLineResidual cost(camera_, observations);
  Eigen::Vector3d residuals;
  Eigen::Matrix<double, 3, 7, Eigen::RowMajor> jacobian;
  jacobian.setConstant(3.0);
  const double* parameters[] = {pose};
  double* jacobian_ptr[] = {jacobian.data()};
  ASSERT_TRUE(cost.Evaluate(parameters, residuals.data(), jacobian_ptr));
  EXPECT_TRUE(cost.valid(0));
  for (int i = 1; i < 3; ++i) {
    EXPECT_FALSE(cost.valid(i));
    EXPECT_EQ(residuals[i], 0.0);
    EXPECT_EQ(jacobian.row(i).cwiseAbs().maxCoeff(), 0.0);
  }
  EXPECT_EQ(cost.num_valid(), 1);
  std::vector<std::uint8_t> valid;
  const auto pixels = cost.ReprojectedPixels(cur_from_ref, &valid);
  EXPECT_EQ(valid, (std::vector<std::uint8_t>{1, 0, 0}));
  EXPECT_NEAR(pixels[1].y(), camera_.height + 5.0, 1e-9);
}

// A shared line error (weighting.h SharedLineErrorWeights): some V (N x 2) and a symmetric M.
SharedLineError RandomSharedLineError(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> value(-0.4, 0.4);
  SharedLineError shared;
  shared.v.resize(n, 2);
  for (int i = 0; i < n; ++i) shared.v.row(i) << value(rng), value(rng);
  shared.m << 0.3, 0.05, 0.05, 0.2;
  return shared;
}

// With a shared line error the rows are (I - V M V^T) e before the loss, e the independent rows;
// the analytic Jacobian of that passes the GradientChecker (with and without the losses).
TEST_F(PointToLineResidualTest, SharedLineErrorMixesTheRowsBeforeTheLoss) {
  constexpr int kRows = 24;
  const auto observations = MakeObservations(kRows, 3);
  const SharedLineError shared = RandomSharedLineError(kRows, 4);
  const PointToLineResidual independent(camera_, observations);
  const PointToLineResidual mixed(camera_, observations, nullptr, shared);
  Eigen::VectorXd e(kRows), r(kRows);
  const double* parameters[] = {pose_};
  ASSERT_TRUE(independent.Evaluate(parameters, e.data(), nullptr));
  ASSERT_TRUE(mixed.Evaluate(parameters, r.data(), nullptr));
  const Eigen::MatrixXd whitening =
      Eigen::MatrixXd::Identity(kRows, kRows) - shared.v * shared.m * shared.v.transpose();
  EXPECT_LT((r - whitening * e).cwiseAbs().maxCoeff(), 1e-12);

  ExpectGradientCheckerPasses(observations, shared);
  EXPECT_THROW(
      PointToLineResidual(camera_, observations, nullptr, RandomSharedLineError(kRows - 1, 4)),
      std::invalid_argument);
}

TEST_F(PointToLineResidualTest, RejectsBadInput) {
  PointToLineObservation good;
  good.pixel_in_ref = Eigen::Vector2d(50, 50);
  good.idepth = 0.3;
  good.line_in_cur = Eigen::Vector3d(1.0, 0.0, -50.0);
  EXPECT_NO_THROW(PointToLineResidual(camera_, {good}));
  EXPECT_THROW(PointToLineResidual(camera_, {}), std::invalid_argument);
  PointToLineObservation bad = good;
  bad.line_in_cur = Eigen::Vector3d(2.0, 0.0, -100.0);  // not normalised
  EXPECT_THROW(PointToLineResidual(camera_, {bad}), std::invalid_argument);
  bad = good;
  bad.idepth = -1.0;
  EXPECT_THROW(PointToLineResidual(camera_, {bad}), std::invalid_argument);
  PinholeCamera broken = camera_;
  broken.fx = 0.0;
  EXPECT_THROW(PointToLineResidual(broken, {good}), std::invalid_argument);
}

}  // namespace
}  // namespace pldvo
