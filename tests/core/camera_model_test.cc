#include "core/camera_model.h"

#include <gtest/gtest.h>

#include <Eigen/SVD>
#include <cmath>
#include <limits>
#include <memory>
#include <opencv2/calib3d.hpp>
#include <random>
#include <stdexcept>
#include <string>

namespace pldvo {
namespace {

constexpr double kPi = 3.14159265358979323846;

PinholeCamera Intrinsics(int width, int height, double fx, double fy, double cx, double cy) {
  return PinholeCamera{width, height, fx, fy, cx, cy};
}

// TUM fr1 (radtan) and a TUM monoVO-like fov camera: the relative calibration
// 0.349153 0.614417 0.503072 0.491986 0.935964 of a 1280x1024 sequence, converted with the DSO
// convention fx = 0.349153 * 1280, cx = 0.503072 * 1280 - 0.5. Scaled to 640x512 for speed.
std::unique_ptr<CameraModel> Pinhole() {
  return MakeCameraModel("pinhole", Intrinsics(640, 480, 535.4, 539.2, 320.1, 247.6), {});
}
std::unique_ptr<CameraModel> Radtan() {
  return MakeCameraModel("radtan", Intrinsics(640, 480, 517.3, 516.5, 318.6, 255.3),
                         {0.2624, -0.9531, -0.0054, 0.0026, 1.1633});
}
std::unique_ptr<CameraModel> Fov() {
  return MakeCameraModel("fov",
                         Intrinsics(640, 512, 0.349153 * 640, 0.614417 * 512, 0.503072 * 640 - 0.5,
                                    0.491986 * 512 - 0.5),
                         {0.935964});
}

std::vector<std::unique_ptr<CameraModel>> AllModels() {
  std::vector<std::unique_ptr<CameraModel>> models;
  models.push_back(Pinhole());
  models.push_back(Radtan());
  models.push_back(Fov());
  return models;
}

// Random points in front of the camera whose projection lies inside the image.
std::vector<Eigen::Vector3d> PointsInView(const CameraModel& camera, int count, unsigned seed) {
  std::mt19937 rng(seed);
  const PinholeCamera& k = camera.intrinsics();
  std::uniform_real_distribution<double> u_dist(0.0, k.width - 1.0), v_dist(0.0, k.height - 1.0),
      depth_dist(0.5, 8.0);
  std::vector<Eigen::Vector3d> points;
  while (static_cast<int>(points.size()) < count) {
    const double v = v_dist(rng), u = u_dist(rng);  // core/random_draws.h
    const Eigen::Vector3d ray = camera.Unproject(Eigen::Vector2d(u, v));
    if (ray.allFinite()) points.push_back(depth_dist(rng) * ray);
  }
  return points;
}

TEST(CameraModelTest, PixelRoundTripOverTheWholeImage) {
  for (const auto& camera : AllModels()) {
    const PinholeCamera& k = camera->intrinsics();
    double max_error = 0.0;
    for (int v = 0; v < k.height; v += 7) {
      for (int u = 0; u < k.width; u += 7) {
        const Eigen::Vector2d pixel(u, v);
        const Eigen::Vector3d ray = camera->Unproject(pixel);
        ASSERT_TRUE(ray.allFinite()) << camera->model_name() << " at " << pixel.transpose();
        EXPECT_DOUBLE_EQ(ray.z(), 1.0);
        max_error = std::max(max_error, (camera->Project(ray) - pixel).norm());
      }
    }
    // Closed-form inverses (pinhole, fov) are exact to round-off; radtan's Newton iteration stops
    // at 1e-14 in normalised units (~5e-12 px). 1e-9 px leaves room for round-off at f ~ 500.
    EXPECT_LT(max_error, 1e-9) << camera->model_name();
  }
}

TEST(CameraModelTest, PointRoundTrip) {
  for (const auto& camera : AllModels()) {
    for (const Eigen::Vector3d& point : PointsInView(*camera, 200, 7)) {
      const Eigen::Vector3d ray = camera->Unproject(camera->Project(point));
      // Same tolerance argument as above, in normalised units (1e-9 px / f ~ 2e-12).
      EXPECT_LT((ray - point / point.z()).norm(), 1e-10) << camera->model_name();
    }
  }
}

TEST(CameraModelTest, JacobianMatchesCentralDifferences) {
  for (const auto& camera : AllModels()) {
    std::vector<Eigen::Vector3d> points = PointsInView(*camera, 100, 11);
    // Near the axis (the fov model's series branch a r < 1e-2) and at the axis.
    points.emplace_back(1e-4, -2e-4, 1.0);
    points.emplace_back(0.0, 0.0, 2.0);
    points.emplace_back(4e-3, 3e-3, 1.0);  // a r ~ 0.0089, just below the series switch
    points.emplace_back(6e-3, 3e-3, 1.0);  // a r ~ 0.012, just above it
    for (const Eigen::Vector3d& point : points) {
      const Eigen::Matrix<double, 2, 3> analytic = camera->ProjectJacobian(point);
      Eigen::Matrix<double, 2, 3> numeric;
      constexpr double kStep = 1e-6;
      for (int i = 0; i < 3; ++i) {
        Eigen::Vector3d delta = Eigen::Vector3d::Zero();
        delta[i] = kStep;
        numeric.col(i) =
            (camera->Project(point + delta) - camera->Project(point - delta)) / (2.0 * kStep);
      }
      // Central differences: truncation h^2 |d^3 u| / 6 ~ 1e-12 * 1e4 (depths >= 0.5 m) and
      // round-off eps |u| / h ~ 2e-16 * 700 / 1e-6 ~ 1e-7 px/m, on entries up to ~2e3 px/m.
      EXPECT_LT((analytic - numeric).cwiseAbs().maxCoeff(), 1e-5)
          << camera->model_name() << " at " << point.transpose() << "\nanalytic\n"
          << analytic << "\nnumeric\n"
          << numeric;
    }
  }
}

TEST(CameraModelTest, RadtanMatchesOpenCvProjectPoints) {
  const auto camera = Radtan();
  const PinholeCamera& k = camera->intrinsics();
  const std::vector<Eigen::Vector3d> points = PointsInView(*camera, 300, 3);
  std::vector<cv::Point3d> object_points;
  for (const Eigen::Vector3d& p : points) object_points.emplace_back(p.x(), p.y(), p.z());
  const cv::Matx33d camera_matrix(k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1);
  std::vector<cv::Point2d> image_points;
  cv::projectPoints(object_points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), camera_matrix,
                    camera->distortion(), image_points);
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector2d pixel = camera->Project(points[i]);
    // The same polynomial in double precision; only the order of operations differs.
    EXPECT_NEAR(pixel.x(), image_points[i].x, 1e-9);
    EXPECT_NEAR(pixel.y(), image_points[i].y, 1e-9);
  }
}

TEST(CameraModelTest, FovFormula) {
  // r_d = atan(2 r tan(w/2)) / w, checked on one point by hand.
  const double w = 0.9;
  const auto camera = MakeCameraModel("fov", Intrinsics(640, 480, 300, 300, 320, 240), {w});
  const Eigen::Vector3d point(0.3, 0.4, 1.0);  // r = 0.5
  const double r_d = std::atan(2.0 * 0.5 * std::tan(w / 2.0)) / w;
  const Eigen::Vector2d expected(320 + 300 * r_d * 0.6, 240 + 300 * r_d * 0.8);
  EXPECT_LT((camera->Project(point) - expected).norm(), 1e-12);
  // Beyond the 90 degree circle r_d w >= pi / 2 there is no ray.
  const double r_d_limit = 0.5 * kPi / w;
  EXPECT_FALSE(camera->Unproject(Eigen::Vector2d(320 + 300 * r_d_limit * 1.01, 240)).allFinite());
}

TEST(CameraModelTest, MakeCameraModelRejectsBadParameters) {
  const PinholeCamera k = Intrinsics(640, 480, 500, 500, 320, 240);
  auto message_of = [](auto&& make) -> std::string {
    try {
      make();
    } catch (const std::invalid_argument& error) {
      return error.what();
    }
    return "no exception";
  };
  EXPECT_NE(message_of([&] { MakeCameraModel("kannala", k, {}); }).find("kannala"),
            std::string::npos);
  EXPECT_NE(message_of([&] {
              MakeCameraModel("radtan", k, {0.1, 0.2});
            }).find("5"),
            std::string::npos);
  EXPECT_NE(message_of([&] { MakeCameraModel("pinhole", k, {0.1}); }).find("0 distortion"),
            std::string::npos);
  EXPECT_NE(message_of([&] { MakeCameraModel("fov", k, {4.0}); }).find("(0, pi)"),
            std::string::npos);
  PinholeCamera bad_focal = k;
  bad_focal.fx = -1.0;
  EXPECT_NE(message_of([&] { MakeCameraModel("pinhole", bad_focal, {}); }).find("focal"),
            std::string::npos);
}

// ---- Undistortion ----

// A smooth checkerboard of period kCheckerPeriod px on the output camera's pixel plane.
constexpr double kCheckerPeriod = 32.0;
constexpr double kCheckerAmplitude = 0.4;
double Checker(const Eigen::Vector2d& q) {
  return 0.5 + kCheckerAmplitude * std::sin(2.0 * kPi * q.x() / kCheckerPeriod) *
                   std::sin(2.0 * kPi * q.y() / kCheckerPeriod);
}

// Renders what the distorted camera sees of a scene drawn on the output pinhole's image plane:
// pixel p of the distorted image shows scene(output.Project(camera.Unproject(p))).
template <typename Scene>
cv::Mat RenderDistorted(const CameraModel& camera, const PinholeCamera& output, Scene scene) {
  const PinholeCamera& k = camera.intrinsics();
  cv::Mat image(k.height, k.width, CV_32FC1);
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const Eigen::Vector3d ray = camera.Unproject(Eigen::Vector2d(u, v));
      image.at<float>(v, u) = ray.allFinite() ? scene(output.Project(ray)) : 0.0f;
    }
  }
  return image;
}

TEST(UndistorterTest, UndistortedCheckerMatchesThePinholeRendering) {
  for (const auto& camera : {Radtan(), Fov()}) {
    const Undistorter undistorter(*camera);
    const PinholeCamera& output = undistorter.output_camera();
    const cv::Mat undistorted = undistorter.Undistort(RenderDistorted(*camera, output, Checker));
    ASSERT_EQ(undistorted.size(), cv::Size(output.width, output.height));
    auto source_of = [&](const Eigen::Vector2d& q) { return camera->Project(output.Unproject(q)); };
    double max_error = 0.0, sum_error = 0.0;
    double min_scale = std::numeric_limits<double>::infinity();  // input px per output px
    int count = 0;
    for (int v = 0; v < output.height; ++v) {
      for (int u = 0; u < output.width; ++u) {
        const Eigen::Vector2d q(u, v);
        // Only pixels whose source lies inside the distorted image (radtan keeps K and has a
        // black border where the barrel-shaped image ends).
        const Eigen::Vector2d source = source_of(q);
        if (!camera->intrinsics().IsInside(source, 1.0)) continue;
        const double error = std::abs(undistorted.at<float>(v, u) - Checker(q));
        max_error = std::max(max_error, error);
        sum_error += error;
        ++count;
        if (u % 8 == 0 && v % 8 == 0) {
          Eigen::Matrix2d map_jacobian;
          map_jacobian << source_of(q + Eigen::Vector2d(0.5, 0)) -
                              source_of(q - Eigen::Vector2d(0.5, 0)),
              source_of(q + Eigen::Vector2d(0, 0.5)) - source_of(q - Eigen::Vector2d(0, 0.5));
          min_scale = std::min(min_scale, map_jacobian.jacobiSvd().singularValues()(1));
        }
      }
    }
    // Bound: in the input image the checker's period shrinks to kCheckerPeriod * min_scale, so
    // |I_xx|, |I_yy| <= A k^2 and |grad I| <= sqrt(2) A k with k = 2 pi / (period * min_scale).
    // Bilinear interpolation errs by <= (h^2 / 8)(|I_xx| + |I_yy|) at h = 1 px, and the 1/32 px
    // map quantisation moves the sample by <= sqrt(2) / 64 px. The map's own curvature adds a
    // term ~1e-4 here, covered by the factor 1.25.
    const double k = 2.0 * kPi / (kCheckerPeriod * min_scale);
    const double bound = 1.25 * (2.0 * kCheckerAmplitude * k * k / 8.0 +
                                 std::sqrt(2.0) / 64.0 * std::sqrt(2.0) * kCheckerAmplitude * k);
    EXPECT_LT(max_error, bound) << camera->model_name();
    EXPECT_GT(count, output.width * output.height / 2);
    std::printf("%s: checker max error %.5f (bound %.5f, min scale %.3f) mean %.5f over %d px\n",
                camera->model_name().c_str(), max_error, bound, min_scale, sum_error / count,
                count);
  }
}

// A point projected with the distorted model appears, after undistortion, at its projection in
// the output pinhole camera: the intensity centroid of a Gaussian blob rendered around it.
TEST(UndistorterTest, BlobLandsAtItsPinholeProjection) {
  for (const auto& camera : {Radtan(), Fov()}) {
    const Undistorter undistorter(*camera);
    const PinholeCamera& output = undistorter.output_camera();
    const PinholeCamera& k = camera->intrinsics();
    double max_offset = 0.0;
    const std::vector<Eigen::Vector2d> targets = {{0.5 * k.width, 0.5 * k.height},
                                                  {0.15 * k.width, 0.2 * k.height},
                                                  {0.85 * k.width, 0.8 * k.height},
                                                  {0.8 * k.width, 0.15 * k.height}};
    for (const Eigen::Vector2d& target : targets) {
      // A 3D point that the distorted camera sees at `target`.
      const Eigen::Vector3d point = 3.0 * camera->Unproject(target);
      ASSERT_LT((camera->Project(point) - target).norm(), 1e-9);
      const Eigen::Vector2d expected = output.Project(point);
      const double sigma = 3.0;
      const cv::Mat undistorted =
          undistorter.Undistort(RenderDistorted(*camera, output, [&](const Eigen::Vector2d& q) {
            return std::exp(-0.5 * (q - expected).squaredNorm() / (sigma * sigma));
          }));
      Eigen::Vector2d weighted_sum = Eigen::Vector2d::Zero();
      double total = 0.0;
      for (int v = std::max(0, int(expected.y()) - 18); v <= int(expected.y()) + 18; ++v) {
        for (int u = std::max(0, int(expected.x()) - 18); u <= int(expected.x()) + 18; ++u) {
          if (u >= output.width || v >= output.height) continue;
          const double value = undistorted.at<float>(v, u);
          weighted_sum += value * Eigen::Vector2d(u, v);
          total += value;
        }
      }
      const Eigen::Vector2d centroid = weighted_sum / total;
      // A wrong map (e.g. the inverse distortion, or a swapped axis) moves the centroid by
      // pixels. What remains is the bias of bilinear resampling of a blob that the distortion
      // squeezes to sigma ~ 1 px in the fov corners (measured max 0.018 px radtan, 0.025 px fov)
      // and the 1/32 px map quantisation.
      max_offset = std::max(max_offset, (centroid - expected).norm());
      EXPECT_LT((centroid - expected).norm(), 0.05)
          << camera->model_name() << " target " << target.transpose() << " centroid "
          << centroid.transpose() << " expected " << expected.transpose();
    }
    std::printf("%s: blob centroid max offset %.4f px\n", camera->model_name().c_str(), max_offset);
  }
}

TEST(UndistorterTest, OutputCameras) {
  // radtan keeps K.
  const auto radtan = Radtan();
  const PinholeCamera radtan_output = Undistorter(*radtan).output_camera();
  EXPECT_EQ(radtan_output.fx, radtan->intrinsics().fx);
  EXPECT_EQ(radtan_output.fy, radtan->intrinsics().fy);
  EXPECT_EQ(radtan_output.cx, radtan->intrinsics().cx);
  EXPECT_EQ(radtan_output.cy, radtan->intrinsics().cy);

  // fov: the widest pinhole whose every pixel samples inside the input; 0.5% wider and some
  // border pixel falls outside.
  const auto fov = Fov();
  const PinholeCamera output = Undistorter(*fov).output_camera();
  EXPECT_EQ(output.width, fov->intrinsics().width);
  EXPECT_EQ(output.cx, fov->intrinsics().cx);
  EXPECT_NEAR(output.fx / fov->intrinsics().fx, output.fy / fov->intrinsics().fy, 1e-12);
  auto all_inside = [&](const PinholeCamera& pinhole) {
    for (int v = 0; v < pinhole.height; ++v) {
      for (int u = 0; u < pinhole.width; ++u) {
        const Eigen::Vector2d source = fov->Project(pinhole.Unproject(Eigen::Vector2d(u, v)));
        if (!fov->intrinsics().IsInside(source, 0.0)) return false;
      }
    }
    return true;
  };
  EXPECT_TRUE(all_inside(output));
  PinholeCamera wider = output;
  wider.fx *= 0.995;
  wider.fy *= 0.995;
  EXPECT_FALSE(all_inside(wider));
  std::printf("fov output camera: fx %.3f fy %.3f (input %.3f %.3f, scale %.4f)\n", output.fx,
              output.fy, fov->intrinsics().fx, fov->intrinsics().fy,
              output.fx / fov->intrinsics().fx);
}

TEST(UndistorterTest, PinholeIsTheIdentity) {
  const auto camera = Pinhole();
  const Undistorter undistorter(*camera);
  EXPECT_TRUE(undistorter.is_identity());
  cv::Mat image(480, 640, CV_8UC1, cv::Scalar(7));
  const cv::Mat result = undistorter.Undistort(image);
  EXPECT_EQ(result.data, image.data);
  EXPECT_EQ(undistorter.output_camera().fx, camera->intrinsics().fx);
}

TEST(UndistorterTest, WrongImageSizeThrowsNamingBothSizes) {
  for (const auto& camera : AllModels()) {
    const Undistorter undistorter(*camera);
    const cv::Mat image(240, 320, CV_8UC1, cv::Scalar(0));
    try {
      undistorter.Undistort(image);
      ADD_FAILURE() << "no exception for " << camera->model_name();
    } catch (const std::invalid_argument& error) {
      const std::string message = error.what();
      EXPECT_NE(message.find("320x240"), std::string::npos) << message;
      const PinholeCamera& k = camera->intrinsics();
      EXPECT_NE(message.find(std::to_string(k.width) + "x" + std::to_string(k.height)),
                std::string::npos)
          << message;
    }
  }
}

TEST(UndistorterTest, WorksOnEightBitAndColourImages) {
  const auto camera = Radtan();
  const Undistorter undistorter(*camera);
  cv::Mat gray(480, 640, CV_8UC1, cv::Scalar(100));
  cv::Mat colour(480, 640, CV_8UC3, cv::Scalar(10, 20, 30));
  const cv::Mat gray_out = undistorter.Undistort(gray);
  const cv::Mat colour_out = undistorter.Undistort(colour);
  EXPECT_EQ(gray_out.type(), CV_8UC1);
  EXPECT_EQ(colour_out.type(), CV_8UC3);
  // The centre samples the inside of a constant image.
  EXPECT_EQ(gray_out.at<uchar>(240, 320), 100);
  EXPECT_EQ(colour_out.at<cv::Vec3b>(240, 320), cv::Vec3b(10, 20, 30));
}

}  // namespace
}  // namespace pldvo
