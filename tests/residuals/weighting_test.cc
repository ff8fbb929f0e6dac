#include "residuals/weighting.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>

#include "tests/residuals/residual_test_utils.h"

namespace pldvo {
namespace {

// Collects the names VisitFields exposes (the config keys).
struct NameCollector {
  std::set<std::string> names;
  template <typename T>
  void Field(const std::string& name, T*, const std::string& doc) {
    EXPECT_FALSE(doc.empty()) << name;
    names.insert(name);
  }
  template <typename Enum>
  void Choice(const std::string& name, Enum*, const ChoiceNames<Enum>& choices,
              const std::string& doc) {
    EXPECT_FALSE(doc.empty()) << name;
    EXPECT_FALSE(choices.empty()) << name;
    names.insert(name);
  }
};

TEST(WeightingOptions, FieldsAndDefaults) {
  WeightingOptions options;
  NameCollector collector;
  options.VisitFields(collector);
  EXPECT_EQ(collector.names,
            (std::set<std::string>{"policy", "sigma_intensity", "line_sigma_px",
                                   "fixed_ratio_lambda", "robust_loss", "robust_threshold"}));
  EXPECT_EQ(options.Check(), "");
  EXPECT_EQ(options.policy, WeightingPolicy::kCovariance);
  EXPECT_EQ(WeightingPolicyNames().size(), 5u);
  options.sigma_intensity = 0.0;
  options.fixed_ratio_lambda = -1.0;
  const std::string error = options.Check();
  EXPECT_NE(error.find("sigma_intensity"), std::string::npos);
  EXPECT_NE(error.find("fixed_ratio_lambda"), std::string::npos);
}

TEST(WeightingOptions, LossFunctions) {
  WeightingOptions options;
  options.robust_threshold = 2.0;
  options.robust_loss = RobustLossKind::kNone;
  EXPECT_EQ(MakeLossFunction(options), nullptr);
  options.robust_loss = RobustLossKind::kHuber;
  double rho[3];
  MakeLossFunction(options)->Evaluate(9.0, rho);  // |r| = 3 > 2: linear zone
  EXPECT_DOUBLE_EQ(rho[0], 2.0 * 2.0 * 3.0 - 4.0);
  options.robust_loss = RobustLossKind::kCauchy;
  MakeLossFunction(options)->Evaluate(9.0, rho);
  EXPECT_NEAR(rho[0], 4.0 * std::log1p(9.0 / 4.0), 1e-12);
  EXPECT_DOUBLE_EQ(LineSigmaAtLevel(options, 2), 0.25);
}

TEST(Weighting, PoliciesFromCovarianceInputs) {
  const Eigen::Vector2d gradient(12.0, -5.0), idepth_jacobian(20.0, 8.0);
  constexpr double kIdepthVar = 1e-3;
  const LineWithCovariance line = FitLine(Eigen::Vector2d(10, 10), Eigen::Vector2d(60, 30), 1.0);
  const Eigen::Vector2d pixel(40.0, 25.0);
  const Eigen::Matrix3d pixel_cov = ReprojectedPixelCovariance(idepth_jacobian, kIdepthVar);

  WeightingOptions options;
  options.sigma_intensity = 3.0;
  options.line_sigma_px = 1.0;
  options.fixed_ratio_lambda = 4.0;
  const double photometric_cov =
      1.0 / std::sqrt(PhotometricVariance(3.0, gradient, idepth_jacobian, kIdepthVar));
  const double line_cov =
      1.0 / std::sqrt(PointToLineVariance(line.line, line.cov, pixel, pixel_cov));
  struct Expected {
    WeightingPolicy policy;
    double photometric;
    double line;
  };
  for (const Expected& e : {Expected{WeightingPolicy::kCovariance, photometric_cov, line_cov},
                            Expected{WeightingPolicy::kUniform, 1.0, 1.0},
                            Expected{WeightingPolicy::kFixedRatio, 1.0 / 3.0, 2.0},
                            Expected{WeightingPolicy::kPhotometricOnly, photometric_cov, 0.0},
                            Expected{WeightingPolicy::kLineOnly, 0.0, line_cov}}) {
    options.policy = e.policy;
    EXPECT_DOUBLE_EQ(PhotometricSqrtInfo(options, gradient, idepth_jacobian, kIdepthVar),
                     e.photometric);
    EXPECT_DOUBLE_EQ(LineSqrtInfo(options, line, pixel, pixel_cov), e.line);
    EXPECT_EQ(UsesPhotometric(e.policy), e.photometric != 0.0);
    EXPECT_EQ(UsesLines(e.policy), e.line != 0.0);
  }
}

TEST(Weighting, GeometryConvenienceMatchesComposition) {
  const PinholeCamera camera = testing_utils::TestCamera();
  const ImagePyramid pyramid(testing_utils::SampleImage(camera, testing_utils::SmoothIntensity), 1);
  const SE3 cur_from_ref = testing_utils::TestCurFromRef();
  const Eigen::Vector2d pixel_in_ref(70.0, 50.0);
  constexpr double kIdepth = 0.4, kIdepthVar = 4e-4;
  const WeightingOptions options;

  Eigen::Vector2d pixel_cur;
  ASSERT_TRUE(Reproject(camera, cur_from_ref, pixel_in_ref, kIdepth, &pixel_cur));
  const Eigen::Vector3f sample = pyramid.Sample(0, pixel_cur.x(), pixel_cur.y());
  const Eigen::Vector2d jacobian =
      ReprojectionIdepthJacobian(camera, cur_from_ref, pixel_in_ref, kIdepth);
  EXPECT_DOUBLE_EQ(
      PhotometricSqrtInfo(options, camera, pyramid, 0, cur_from_ref, pixel_in_ref, kIdepth,
                          kIdepthVar),
      PhotometricSqrtInfo(options, Eigen::Vector2d(sample[1], sample[2]), jacobian, kIdepthVar));
  const LineWithCovariance line =
      FitLine(pixel_cur + Eigen::Vector2d(-20, 3), pixel_cur + Eigen::Vector2d(20, 5), 1.0);
  EXPECT_DOUBLE_EQ(
      LineSqrtInfo(options, camera, cur_from_ref, pixel_in_ref, kIdepth, kIdepthVar, line),
      LineSqrtInfo(options, line, pixel_cur, ReprojectedPixelCovariance(jacobian, kIdepthVar)));
  // Out of the image: no information.
  EXPECT_EQ(PhotometricSqrtInfo(options, camera, pyramid, 0, cur_from_ref,
                                Eigen::Vector2d(-200.0, 50.0), kIdepth, kIdepthVar),
            0.0);
}

}  // namespace
}  // namespace pldvo
