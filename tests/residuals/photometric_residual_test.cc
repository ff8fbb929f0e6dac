#include "residuals/photometric_residual.h"

#include <ceres/autodiff_cost_function.h>
#include <ceres/cubic_interpolation.h>
#include <ceres/gradient_checker.h>
#include <ceres/loss_function.h>
#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <stdexcept>

#include "residuals/robustify.h"
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
constexpr double kLossScale = 1.0;  // whitened units

std::unique_ptr<ceres::LossFunction> MakeLoss(Loss loss) {
  if (loss == Loss::kHuber) return std::make_unique<ceres::HuberLoss>(kLossScale);
  if (loss == Loss::kCauchy) return std::make_unique<ceres::CauchyLoss>(kLossScale);
  return nullptr;
}

// The autodiff twin: same residual written with Jets and a Jet-aware sampler: for bilinear the
// test sampler with the analytic model's gradient, for bicubic ceres::BiCubicInterpolator's own
// Jet overload (the chain rule through the interpolant done by Ceres, not by our code).
struct PhotometricTwin {
  using Grid = ceres::Grid2D<float, 1>;
  PhotometricTwin(const ImagePyramid& pyramid, const PinholeCamera& camera,
                  const std::vector<PhotometricObservation>& observations, Loss loss,
                  ImageInterpolation interpolation)
      : pyramid(pyramid),
        camera(camera),
        observations(observations),
        loss(loss),
        interpolation(interpolation),
        grid(pyramid.IntensityData(0), 0, pyramid.height(0), 0, pyramid.width(0)),
        bicubic(grid) {}

  template <typename T>
  T Sample(const T& u, const T& v) const {
    if (interpolation == ImageInterpolation::kBilinear) {
      return testing_utils::SampleIntensity(pyramid, 0, u, v);
    }
    T intensity;
    bicubic.Evaluate(v, u, &intensity);
    return intensity;
  }

  template <typename T>
  bool operator()(const T* pose, T* residuals) const {
    Eigen::Quaternion<T> rotation(pose[6], pose[3], pose[4], pose[5]);
    rotation.normalize();
    const Eigen::Matrix<T, 3, 1> translation(pose[0], pose[1], pose[2]);
    for (size_t i = 0; i < observations.size(); ++i) {
      const PhotometricObservation& o = observations[i];
      const Eigen::Matrix<T, 3, 1> ray = camera.Unproject(o.pixel_in_ref).cast<T>();
      const Eigen::Matrix<T, 3, 1> q = rotation * ray + T(o.idepth) * translation;
      const T u = T(camera.fx) * q.x() / q.z() + T(camera.cx);
      const T v = T(camera.fy) * q.y() / q.z() + T(camera.cy);
      const T r = T(o.sqrt_info) * (T(o.intensity_ref) - Sample(u, v));
      if (loss == Loss::kHuber) {
        residuals[i] = testing_utils::HuberSqrtForm(r, kLossScale);
      } else if (loss == Loss::kCauchy) {
        residuals[i] = testing_utils::CauchySqrtForm(r, kLossScale);
      } else {
        residuals[i] = r;
      }
    }
    return true;
  }

  const ImagePyramid& pyramid;
  const PinholeCamera camera;
  const std::vector<PhotometricObservation> observations;
  const Loss loss;
  const ImageInterpolation interpolation;
  const Grid grid;
  const ceres::BiCubicInterpolator<Grid> bicubic;
};

// Where the observations reproject in the current image: random sub-pixel positions, bilinear
// cell centres (x + 0.5, y + 0.5), or cell corners (integer x and y: every finite difference
// straddles a cell boundary in both directions).
enum class Placement { kRandom, kCellCentres, kCellCorners };

constexpr ImageInterpolation kInterpolations[] = {ImageInterpolation::kBilinear,
                                                  ImageInterpolation::kBicubic};

class PhotometricResidualTest : public ::testing::Test {
 protected:
  PhotometricResidualTest()
      : camera_(TestCamera()),
        smooth_(testing_utils::SampleImage(camera_, testing_utils::SmoothIntensity), 1),
        ramp_(testing_utils::SampleImage(camera_, testing_utils::RampIntensity), 1),
        cur_from_ref_(TestCurFromRef()) {
    PoseToParameters(cur_from_ref_, pose_);
  }

  // `count` reference pixels reprojecting into the interior of the current image as `placement`
  // says. Reference
  // intensities are offset from the current ones so that the whitened residuals span both
  // zones of the robust losses.
  std::vector<PhotometricObservation> MakeObservations(const ImagePyramid& pyramid, int count,
                                                       Placement placement, unsigned seed) const {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u_dist(10.0, camera_.width - 11.0);
    std::uniform_real_distribution<double> v_dist(10.0, camera_.height - 11.0);
    std::uniform_real_distribution<double> depth_dist(1.5, 5.0);
    std::uniform_real_distribution<double> inlier_dist(0.2, 0.8);
    std::uniform_real_distribution<double> outlier_dist(1.3, 3.0);
    std::uniform_real_distribution<double> sqrt_info_dist(0.3, 0.6);
    std::vector<PhotometricObservation> observations;
    for (int i = 0; i < count; ++i) {
      const double v = v_dist(rng), u = u_dist(rng);  // core/random_draws.h
      Eigen::Vector2d pixel_in_cur(u, v);
      if (placement == Placement::kCellCentres) pixel_in_cur = pixel_in_cur.array().floor() + 0.5;
      if (placement == Placement::kCellCorners) pixel_in_cur = pixel_in_cur.array().round();
      PhotometricObservation o;
      PlaceReferencePixel(camera_, cur_from_ref_, pixel_in_cur, depth_dist(rng), &o.pixel_in_ref,
                          &o.idepth);
      // Whitened residual +-(0.2 .. 0.8) or +-(1.3 .. 3.0): away from the Huber kink at 1,
      // where the robustified row is only C1 and numeric differences would straddle it.
      const double whitened =
          (i % 2 == 0 ? 1.0 : -1.0) * (i % 4 < 2 ? inlier_dist(rng) : outlier_dist(rng));
      o.sqrt_info = sqrt_info_dist(rng);
      o.intensity_ref =
          pyramid.Sample(0, pixel_in_cur.x(), pixel_in_cur.y())[0] + whitened / o.sqrt_info;
      observations.push_back(o);
    }
    return observations;
  }

  // Runs ceres::GradientChecker with the SE3Manifold. GradientChecker's own criterion is
  // per entry, relative to the entry; `entry_tolerance` applies it. Entries that nearly cancel
  // are small while the float32 rounding noise of the numeric derivative is not, so the
  // meaningful bound is on the error relative to the largest entry of the row:
  // `row_tolerance`. Returns {worst per-entry, worst row-relative} error.
  std::pair<double, double> GradientCheck(const ceres::CostFunction& cost,
                                          double relative_initial_step, double entry_tolerance,
                                          double row_tolerance) const {
    const SE3Manifold manifold;
    const std::vector<const ceres::Manifold*> manifolds = {&manifold};
    ceres::NumericDiffOptions options;
    options.ridders_relative_initial_step_size = relative_initial_step;
    const ceres::GradientChecker checker(&cost, &manifolds, options);
    ceres::GradientChecker::ProbeResults results;
    const double* parameters[] = {pose_};
    EXPECT_TRUE(checker.Probe(parameters, entry_tolerance, &results)) << results.error_log;
    const Eigen::MatrixXd& analytic = results.local_jacobians[0];
    const Eigen::MatrixXd& numeric = results.local_numeric_jacobians[0];
    double worst_row = 0.0;
    for (int i = 0; i < analytic.rows(); ++i) {
      worst_row = std::max(worst_row, (analytic.row(i) - numeric.row(i)).cwiseAbs().maxCoeff() /
                                          analytic.row(i).cwiseAbs().maxCoeff());
    }
    EXPECT_LT(worst_row, row_tolerance);
    return {results.maximum_relative_error, worst_row};
  }

  PinholeCamera camera_;
  ImagePyramid smooth_;
  ImagePyramid ramp_;
  SE3 cur_from_ref_;
  double pose_[7];
};

// Analytic == autodiff twin (same sampling model), compared in the tangent space where both
// are defined uniquely. Agreement is to rounding: 1e-9 relative to the largest entry.
TEST_F(PhotometricResidualTest, AnalyticMatchesAutoDiff) {
  for (const ImageInterpolation interpolation : kInterpolations) {
    for (const Loss loss_kind : {Loss::kNone, Loss::kHuber, Loss::kCauchy}) {
      const auto loss = MakeLoss(loss_kind);
      const auto observations = MakeObservations(smooth_, 40, Placement::kRandom, 1);
      const PhotometricResidual analytic(smooth_, 0, camera_, observations, loss.get(),
                                         interpolation);
      ceres::AutoDiffCostFunction<PhotometricTwin, ceres::DYNAMIC, 7> twin(
          new PhotometricTwin(smooth_, camera_, observations, loss_kind, interpolation),
          static_cast<int>(observations.size()));
      const int n = static_cast<int>(observations.size());
      const TwinComparison c = CompareWithTwin(analytic, twin, pose_, n);
      ASSERT_TRUE(c.evaluated);
      EXPECT_EQ(analytic.num_valid(), n);
      EXPECT_LT(c.max_residual_difference, 1e-9);
      EXPECT_LT(c.max_tangent_difference, 1e-9 * c.tangent_scale)
          << "loss " << static_cast<int>(loss_kind) << " interpolation "
          << static_cast<int>(interpolation);
      // EvaluateTangent gives the same rows directly.
      Eigen::VectorXd r_tangent(n);
      Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor> j_tangent(n, 6);
      analytic.EvaluateTangent(cur_from_ref_, r_tangent.data(), j_tangent.data(), nullptr);
      EXPECT_LT((r_tangent - c.residuals).cwiseAbs().maxCoeff(), 1e-12);
      EXPECT_LT((Eigen::MatrixXd(j_tangent) - c.tangent_jacobian).cwiseAbs().maxCoeff(),
                1e-9 * c.tangent_scale);
    }
  }
}

// GradientChecker tolerances. Ceres' own criterion is per entry relative to that entry; entries
// that nearly cancel (|J_ij| << max_j |J_ij|) carry the same absolute rounding noise as the
// others, so it is applied loosely (kEntryTolerance) and the real bound is on the error relative
// to the row's largest entry (see GradientCheck). Step sizes: Ridders from a 1e-3 relative
// step moves the reprojection by 0.005 .. 0.05 px, inside one bilinear cell; 1e-2 is too large
// for the quaternion's qw ~ 1 (measured 27% row error from the numeric side), 1e-5 too small
// for float32 images (see GradientCheckerPerPixelSmallStep).
constexpr double kEntryTolerance = 0.5;

// On a linear ramp, bilinear interpolation and central differences are exact, so numeric
// differentiation of the interpolated residual sees exactly the analytic model at any sub-pixel
// position. What remains is the float32 storage of the image (~1e-5 gray levels of rounding per
// sample). Measured row-relative error: 2.4e-5 without loss, 1.4e-4 with Huber / Cauchy rows;
// bound 5e-4.
TEST_F(PhotometricResidualTest, GradientCheckerOnRampImageIsTight) {
  for (const Loss loss_kind : {Loss::kNone, Loss::kHuber, Loss::kCauchy}) {
    const auto loss = MakeLoss(loss_kind);
    const PhotometricResidual cost(ramp_, 0, camera_,
                                   MakeObservations(ramp_, 30, Placement::kRandom, 2), loss.get());
    GradientCheck(cost, 1e-3, kEntryTolerance, 5e-4);
  }
}

// On the smooth texture the analytic Jacobian uses the interpolated central-difference
// gradient while numeric differentiation sees the derivative of the bilinear interpolant. At a
// cell centre both approximate the true derivative to second order, but with different
// constants (central difference h^2 f'''/6 plus interpolation h^2 f'''/8, against the forward
// difference's h^2 f'''/24 and the cross-row average's h^2 f_xyy/8): about k^2 / 4 = 1.2 .. 1.5%
// for the texture's wavenumbers k = 0.22 .. 0.24 /px, per gradient component. Measured
// row-relative error 2.9%; bound 5%. (Bicubic sampling has no such model error, see below.)
TEST_F(PhotometricResidualTest, GradientCheckerOnSmoothImageAtCellCentres) {
  for (const Loss loss_kind : {Loss::kNone, Loss::kHuber, Loss::kCauchy}) {
    const auto loss = MakeLoss(loss_kind);
    const PhotometricResidual cost(
        smooth_, 0, camera_, MakeObservations(smooth_, 30, Placement::kCellCentres, 3), loss.get());
    GradientCheck(cost, 1e-3, kEntryTolerance, 5e-2);
  }
}

// N = 1 (the per-pixel form) with the style's relative step 1e-5: the reprojection moves by
// only ~1e-4 px and float32 rounding of the sample (~1e-5 gray levels) becomes ~1% of the
// difference, on top of the 3% model difference above (measured: per entry <= 2.0%, per row
// <= 1.3%). Bound 5% for both.
TEST_F(PhotometricResidualTest, GradientCheckerPerPixelSmallStep) {
  const auto observations = MakeObservations(smooth_, 5, Placement::kCellCentres, 4);
  for (const auto& observation : observations) {
    const PhotometricResidual cost(smooth_, 0, camera_, {observation});
    GradientCheck(cost, 1e-5, 5e-2, 5e-2);
  }
}

// Bicubic: the residual is a C1 function of the pose whose Jacobian is its exact derivative,
// and the interpolant is evaluated in double from the float32 samples (constants), so numeric
// differentiation sees no float32 rounding: with the style's relative step 1e-5 (the
// reprojection moves ~1e-4 px) the check is tight at any sub-pixel position. What remains is
// the O(h) error of a difference that straddles a cell boundary, where the interpolant's second
// derivative jumps (at cell corners every difference does). Measured worst row-relative error
// over 100 rows: 3.6e-5 at random positions, 9.9e-6 at cell corners (bilinear: 1.3 .. 2.9%,
// tests above); bound 1e-4, and 1e-3 per entry (GradientChecker's own criterion; measured
// 2.3e-4 for entries that nearly cancel).
TEST_F(PhotometricResidualTest, GradientCheckerBicubicIsExactOnSmoothImage) {
  for (const Placement placement : {Placement::kRandom, Placement::kCellCorners}) {
    for (const Loss loss_kind : {Loss::kNone, Loss::kHuber, Loss::kCauchy}) {
      const auto loss = MakeLoss(loss_kind);
      const PhotometricResidual cost(smooth_, 0, camera_,
                                     MakeObservations(smooth_, 100, placement, 7), loss.get(),
                                     ImageInterpolation::kBicubic);
      GradientCheck(cost, 1e-5, 1e-3, 1e-4);
    }
  }
}

// N = 1 (the per-pixel form) with bicubic sampling and the same step: measured per entry
// <= 5.2e-6 (the worst where a difference straddles a cell boundary, 1e-11 elsewhere); bound
// 1e-4 for entries and rows (bilinear needs 5%, GradientCheckerPerPixelSmallStep).
TEST_F(PhotometricResidualTest, GradientCheckerBicubicPerPixelSmallStep) {
  const auto observations = MakeObservations(smooth_, 5, Placement::kRandom, 8);
  for (const auto& observation : observations) {
    const PhotometricResidual cost(smooth_, 0, camera_, {observation}, nullptr,
                                   ImageInterpolation::kBicubic);
    GradientCheck(cost, 1e-5, 1e-4, 1e-4);
  }
}

// Affine brightness (residuals/affine_brightness.h): both blocks against ceres::GradientChecker
// (pose through the SE3Manifold, {a, b} Euclidean), bicubic so that the check is tight as in
// GradientCheckerBicubicIsExactOnSmoothImage. The brightness rows e^a I_ref + b are linear in b
// and smooth in a, so their part is exact to the numeric difference's rounding. Bounds: 1e-3
// per entry, 1e-4 per row (of both blocks together).
TEST_F(PhotometricResidualTest, GradientCheckerWithAffineBrightness) {
  const double brightness[kBrightnessSize] = {0.15, -7.0};
  for (const Loss loss_kind : {Loss::kNone, Loss::kHuber, Loss::kCauchy}) {
    const auto loss = MakeLoss(loss_kind);
    const PhotometricResidual cost(smooth_, 0, camera_,
                                   MakeObservations(smooth_, 60, Placement::kRandom, 9), loss.get(),
                                   ImageInterpolation::kBicubic, BrightnessModel::kAffine);
    ASSERT_EQ(cost.parameter_block_sizes().size(), 2u);
    const SE3Manifold manifold;
    const std::vector<const ceres::Manifold*> manifolds = {&manifold, nullptr};
    ceres::NumericDiffOptions options;
    options.ridders_relative_initial_step_size = 1e-5;
    const ceres::GradientChecker checker(&cost, &manifolds, options);
    ceres::GradientChecker::ProbeResults results;
    const double* parameters[] = {pose_, brightness};
    EXPECT_TRUE(checker.Probe(parameters, 1e-3, &results)) << results.error_log;
    const int n = cost.num_residuals();
    Eigen::MatrixXd analytic(n, 8), numeric(n, 8);
    analytic << results.local_jacobians[0], results.local_jacobians[1];
    numeric << results.local_numeric_jacobians[0], results.local_numeric_jacobians[1];
    double worst_row = 0.0;
    for (int i = 0; i < n; ++i) {
      worst_row = std::max(worst_row, (analytic.row(i) - numeric.row(i)).cwiseAbs().maxCoeff() /
                                          analytic.row(i).cwiseAbs().maxCoeff());
    }
    EXPECT_LT(worst_row, 1e-4) << "loss " << static_cast<int>(loss_kind);
  }
}

// At a = b = 0 the affine rows and pose Jacobian are the plain rows, bit for bit; at (a, b) the
// row is e^{-a/2} times the plain row of the reference intensity e^a I_ref + b.
TEST_F(PhotometricResidualTest, AffineBrightnessRowsAreTheTransferredPlainRows) {
  const auto observations = MakeObservations(smooth_, 50, Placement::kRandom, 10);
  const int n = static_cast<int>(observations.size());
  const PhotometricResidual plain(smooth_, 0, camera_, observations);
  const PhotometricResidual affine(smooth_, 0, camera_, observations, nullptr,
                                   ImageInterpolation::kBilinear, BrightnessModel::kAffine);
  Eigen::VectorXd r_plain(n), r_affine(n);
  Eigen::Matrix<double, Eigen::Dynamic, 7, Eigen::RowMajor> j_plain(n, 7), j_affine(n, 7);
  Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor> j_brightness(n, 2);
  const double identity[kBrightnessSize] = {0.0, 0.0};
  const double* plain_parameters[] = {pose_};
  const double* affine_parameters[] = {pose_, identity};
  double* plain_jacobians[] = {j_plain.data()};
  double* affine_jacobians[] = {j_affine.data(), j_brightness.data()};
  ASSERT_TRUE(plain.Evaluate(plain_parameters, r_plain.data(), plain_jacobians));
  ASSERT_TRUE(affine.Evaluate(affine_parameters, r_affine.data(), affine_jacobians));
  EXPECT_EQ(r_plain, r_affine);
  EXPECT_EQ(Eigen::MatrixXd(j_plain), Eigen::MatrixXd(j_affine));
  // dr/da = w (I_ref + I_cur) / 2 = w I_ref - r / 2, dr/db = w.
  for (int i = 0; i < n; ++i) {
    const double w = observations[i].sqrt_info;
    EXPECT_NEAR(j_brightness(i, 0), w * observations[i].intensity_ref - 0.5 * r_plain[i], 1e-12);
    EXPECT_DOUBLE_EQ(j_brightness(i, 1), w);
  }
  const double brightness[kBrightnessSize] = {-0.2, 11.0};
  std::vector<PhotometricObservation> transferred = observations;
  for (PhotometricObservation& o : transferred) {
    o.intensity_ref = std::exp(brightness[0]) * o.intensity_ref + brightness[1];
  }
  const PhotometricResidual transferred_plain(smooth_, 0, camera_, transferred);
  const double* transferred_parameters[] = {pose_, brightness};
  ASSERT_TRUE(transferred_plain.Evaluate(plain_parameters, r_plain.data(), nullptr));
  ASSERT_TRUE(affine.Evaluate(transferred_parameters, r_affine.data(), nullptr));
  EXPECT_LT((std::exp(-0.5 * brightness[0]) * r_plain - r_affine).cwiseAbs().maxCoeff(), 1e-12);
}

TEST_F(PhotometricResidualTest, RobustRowsSumToRobustCost) {
  const auto observations = MakeObservations(smooth_, 50, Placement::kRandom, 5);
  const int n = static_cast<int>(observations.size());
  for (const Loss loss_kind : {Loss::kHuber, Loss::kCauchy}) {
    const auto loss = MakeLoss(loss_kind);
    const PhotometricResidual plain(smooth_, 0, camera_, observations);
    const PhotometricResidual robust(smooth_, 0, camera_, observations, loss.get());
    Eigen::VectorXd r_plain(n), r_robust(n);
    const double* parameters[] = {pose_};
    plain.Evaluate(parameters, r_plain.data(), nullptr);
    robust.Evaluate(parameters, r_robust.data(), nullptr);
    double expected = 0.0;
    int outliers = 0;
    for (int i = 0; i < n; ++i) {
      double rho[3];
      loss->Evaluate(r_plain[i] * r_plain[i], rho);
      expected += rho[0];
      outliers += std::abs(r_plain[i]) > kLossScale;
      EXPECT_EQ(r_robust[i] >= 0.0, r_plain[i] >= 0.0);
    }
    EXPECT_GT(outliers, 5);  // both zones of the loss are exercised
    EXPECT_NEAR(r_robust.squaredNorm(), expected, 1e-12 * expected);
  }
  // The derivative of the square-root form tends to 1 at r = 0.
  ceres::HuberLoss huber(1.0);
  ceres::CauchyLoss cauchy(1.0);
  for (const ceres::LossFunction* loss :
       {static_cast<ceres::LossFunction*>(&huber), static_cast<ceres::LossFunction*>(&cauchy)}) {
    for (const double r : {0.0, 1e-200, 1e-8, -1e-8}) {
      double scale;
      RobustifyRow(loss, r, &scale);
      EXPECT_NEAR(scale, 1.0, 1e-12) << r;
    }
  }
}

// IntensityErrors are the rows without weight and loss: I_ref - I_cur, whatever the loss.
TEST_F(PhotometricResidualTest, IntensityErrorsAreTheUnweightedRows) {
  const auto observations = MakeObservations(smooth_, 50, Placement::kRandom, 7);
  const int n = static_cast<int>(observations.size());
  const auto loss = MakeLoss(Loss::kHuber);
  for (const ImageInterpolation interpolation : kInterpolations) {
    const PhotometricResidual plain(smooth_, 0, camera_, observations, nullptr, interpolation);
    const PhotometricResidual robust(smooth_, 0, camera_, observations, loss.get(), interpolation);
    Eigen::VectorXd r_plain(n), errors(n);
    std::vector<std::uint8_t> valid(n, 0);
    const double* parameters[] = {pose_};
    plain.Evaluate(parameters, r_plain.data(), nullptr);
    robust.IntensityErrors(cur_from_ref_, errors.data(), valid.data());
    for (int i = 0; i < n; ++i) {
      ASSERT_TRUE(valid[i]);
      EXPECT_NEAR(errors[i] * observations[i].sqrt_info, r_plain[i], 1e-9) << i;
    }
  }
}

TEST_F(PhotometricResidualTest, BatchRowsEqualPerPixelForm) {
  for (const ImageInterpolation interpolation : kInterpolations) {
    const auto observations = MakeObservations(smooth_, 10, Placement::kRandom, 6);
    const PhotometricResidual batch(smooth_, 0, camera_, observations, nullptr, interpolation);
    Eigen::VectorXd r_batch(10);
    Eigen::Matrix<double, 10, 7, Eigen::RowMajor> j_batch;
    const double* parameters[] = {pose_};
    double* j_batch_ptr[] = {j_batch.data()};
    batch.Evaluate(parameters, r_batch.data(), j_batch_ptr);
    for (int i = 0; i < 10; ++i) {
      const PhotometricResidual single(smooth_, 0, camera_, {observations[i]}, nullptr,
                                       interpolation);
      double r;
      Eigen::Matrix<double, 1, 7> j;
      double* j_ptr[] = {j.data()};
      single.Evaluate(parameters, &r, j_ptr);
      EXPECT_EQ(r, r_batch[i]);
      EXPECT_EQ((j - j_batch.row(i)).cwiseAbs().maxCoeff(), 0.0);
    }
  }
}

TEST_F(PhotometricResidualTest, InvalidRowsAreZeroAndFlagged) {
  // The current camera moved 1 m forward, so reference points nearer than 1 m are behind it.
  const SE3 cur_from_ref(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.05, -0.02, -1.0));
  double pose[7];
  PoseToParameters(cur_from_ref, pose);
  std::vector<PhotometricObservation> observations(4);
  // Row 0: valid. Row 1: reprojects far left of the image. Row 2: behind the current camera
  // (reference depth 0.5 m). Row 3: in the one-pixel border where the gradient is undefined.
  PlaceReferencePixel(camera_, cur_from_ref, Eigen::Vector2d(60.0, 50.0), 3.0,
                      &observations[0].pixel_in_ref, &observations[0].idepth);
  PlaceReferencePixel(camera_, cur_from_ref, Eigen::Vector2d(-30.0, 50.0), 3.0,
                      &observations[1].pixel_in_ref, &observations[1].idepth);
  observations[2].pixel_in_ref = Eigen::Vector2d(80.0, 60.0);
  observations[2].idepth = 2.0;
  PlaceReferencePixel(camera_, cur_from_ref, Eigen::Vector2d(0.5, 50.0), 3.0,
                      &observations[3].pixel_in_ref, &observations[3].idepth);
  for (auto& o : observations) o.intensity_ref = 300.0;  // nonzero residual when valid
  // The same rule for both interpolations.
  for (const ImageInterpolation interpolation : kInterpolations) {
    const PhotometricResidual cost(smooth_, 0, camera_, observations, nullptr, interpolation);
    Eigen::Vector4d residuals;
    Eigen::Matrix<double, 4, 7, Eigen::RowMajor> jacobian;
    jacobian.setConstant(7.0);
    const double* parameters[] = {pose};
    double* jacobian_ptr[] = {jacobian.data()};
    ASSERT_TRUE(cost.Evaluate(parameters, residuals.data(), jacobian_ptr));
    EXPECT_TRUE(cost.valid(0));
    EXPECT_NE(residuals[0], 0.0);
    for (int i = 1; i < 4; ++i) {
      EXPECT_FALSE(cost.valid(i)) << i;
      EXPECT_EQ(residuals[i], 0.0) << i;
      EXPECT_EQ(jacobian.row(i).cwiseAbs().maxCoeff(), 0.0) << i;
    }
    EXPECT_EQ(cost.num_valid(), 1);

    std::vector<std::uint8_t> valid;
    const std::vector<Eigen::Vector2d> pixels = cost.ReprojectedPixels(cur_from_ref, &valid);
    EXPECT_EQ(valid, (std::vector<std::uint8_t>{1, 0, 0, 0}));
    EXPECT_NEAR(pixels[1].x(), -30.0, 1e-9);
    EXPECT_TRUE(std::isnan(pixels[2].x()));
    std::uint8_t tangent_valid[4];
    double tangent_residuals[4];
    cost.EvaluateTangent(cur_from_ref, tangent_residuals, nullptr, tangent_valid);
    EXPECT_EQ(tangent_valid[0], 1);
    EXPECT_EQ(tangent_valid[2], 0);
    std::uint8_t error_valid[4];
    double errors[4];
    cost.IntensityErrors(cur_from_ref, errors, error_valid);
    EXPECT_EQ(std::vector<std::uint8_t>(error_valid, error_valid + 4),
              (std::vector<std::uint8_t>{1, 0, 0, 0}));
    EXPECT_EQ(errors[0], residuals[0]);  // sqrt_info 1, no loss
    EXPECT_EQ(errors[2], 0.0);
  }
}

TEST_F(PhotometricResidualTest, ReprojectedPixelsHitTheirTargets) {
  PhotometricObservation o;
  PlaceReferencePixel(camera_, cur_from_ref_, Eigen::Vector2d(42.25, 71.75), 2.5, &o.pixel_in_ref,
                      &o.idepth);
  const PhotometricResidual cost(smooth_, 0, camera_, {o});
  const auto pixels = cost.ReprojectedPixels(cur_from_ref_);
  EXPECT_LT((pixels[0] - Eigen::Vector2d(42.25, 71.75)).norm(), 1e-9);
}

TEST_F(PhotometricResidualTest, RejectsBadInput) {
  PhotometricObservation good;
  good.pixel_in_ref = Eigen::Vector2d(50, 50);
  good.idepth = 0.3;
  EXPECT_THROW(PhotometricResidual(smooth_, 0, camera_, {}), std::invalid_argument);
  EXPECT_THROW(PhotometricResidual(smooth_, 1, camera_, {good}), std::invalid_argument);
  EXPECT_THROW(PhotometricResidual(smooth_, 0, camera_.AtLevel(1), {good}), std::invalid_argument);
  PhotometricObservation bad = good;
  bad.idepth = -0.1;
  EXPECT_THROW(PhotometricResidual(smooth_, 0, camera_, {bad}), std::invalid_argument);
  bad = good;
  bad.sqrt_info = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(PhotometricResidual(smooth_, 0, camera_, {bad}), std::invalid_argument);
  // idepth = 0 (a point at infinity) is allowed: the translation then has no effect.
  PhotometricObservation at_infinity = good;
  at_infinity.idepth = 0.0;
  const PhotometricResidual cost(smooth_, 0, camera_, {at_infinity});
  double jacobian[6];
  double residual;
  cost.EvaluateTangent(cur_from_ref_, &residual, jacobian, nullptr);
  EXPECT_EQ(jacobian[0], 0.0);
  EXPECT_EQ(jacobian[1], 0.0);
  EXPECT_EQ(jacobian[2], 0.0);
  EXPECT_NE(jacobian[3], 0.0);
}

}  // namespace
}  // namespace pldvo
