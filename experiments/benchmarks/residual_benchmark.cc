// Evaluate() of the batched residuals with Jacobians, for a batch of 10 000 pixels on a
// 640x480 image: the per-pixel cost of the inner loop of tracking. The photometric benchmarks
// take the image interpolation as argument `bicubic` (0 = bilinear, 1 = bicubic).
//   build/experiments/benchmarks/residual_benchmark
// items_per_second counts pixels (rows), so 1 / items_per_second is the time per pixel.
#include <benchmark/benchmark.h>
#include <ceres/loss_function.h>

#include <cmath>
#include <random>
#include <vector>

#include "core/image_pyramid.h"
#include "core/pinhole_camera.h"
#include "core/se3.h"
#include "residuals/photometric_residual.h"
#include "residuals/point_to_line_residual.h"
#include "residuals/se3_manifold.h"

namespace pldvo {
namespace {

constexpr int kBatch = 10000;

struct Scene {
  PinholeCamera camera;
  ImagePyramid pyramid;
  SE3 cur_from_ref;
  std::vector<PhotometricObservation> photometric;
  std::vector<PointToLineObservation> lines;

  Scene() {
    camera = PinholeCamera{640, 480, 500.0, 500.0, 319.5, 239.5};
    cv::Mat image(camera.height, camera.width, CV_32F);
    for (int y = 0; y < image.rows; ++y) {
      for (int x = 0; x < image.cols; ++x) {
        image.at<float>(y, x) = static_cast<float>(
            128.0 + 60.0 * std::sin(x / 7.0) * std::cos(y / 5.0) + 20.0 * std::sin((x + y) / 11.0));
      }
    }
    pyramid = ImagePyramid(image, 1);
    Vector6d twist;
    twist << 0.05, -0.02, 0.03, 0.01, -0.02, 0.005;
    cur_from_ref = SE3::Exp(twist);
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> u(40.0, camera.width - 40.0),
        v(40.0, camera.height - 40.0), idepth(0.2, 1.0), angle(0.0, 6.28);
    for (int i = 0; i < kBatch; ++i) {
      PhotometricObservation o;
      const double y = v(rng), x = u(rng);  // core/random_draws.h
      o.pixel_in_ref = Eigen::Vector2d(x, y);
      o.idepth = idepth(rng);
      o.intensity_ref = 128.0;
      o.sqrt_info = 0.2;
      photometric.push_back(o);
      PointToLineObservation l;
      l.pixel_in_ref = o.pixel_in_ref;
      l.idepth = o.idepth;
      const double a = angle(rng);
      l.line_in_cur = Eigen::Vector3d(std::cos(a), std::sin(a), -300.0);
      l.sqrt_info = 1.0;
      lines.push_back(l);
    }
  }
};

const Scene& GetScene() {
  static const Scene scene;
  return scene;
}

template <typename Cost>
void RunEvaluate(benchmark::State& state, const Cost& cost) {
  const Scene& scene = GetScene();
  double pose[7];
  PoseToParameters(scene.cur_from_ref, pose);
  std::vector<double> residuals(kBatch), jacobian(kBatch * 7);
  const double* parameters[] = {pose};
  double* jacobians[] = {jacobian.data()};
  for (auto _ : state) {
    cost.Evaluate(parameters, residuals.data(), state.range(0) != 0 ? jacobians : nullptr);
    benchmark::DoNotOptimize(residuals.data());
    benchmark::DoNotOptimize(jacobian.data());
  }
  state.SetItemsProcessed(state.iterations() * kBatch);
  state.counters["valid"] = cost.num_valid();
}

ImageInterpolation InterpolationArg(const benchmark::State& state, int index) {
  return state.range(index) != 0 ? ImageInterpolation::kBicubic : ImageInterpolation::kBilinear;
}

void BM_PhotometricEvaluate(benchmark::State& state) {
  const Scene& scene = GetScene();
  const PhotometricResidual cost(scene.pyramid, 0, scene.camera, scene.photometric, nullptr,
                                 InterpolationArg(state, 1));
  RunEvaluate(state, cost);
}
BENCHMARK(BM_PhotometricEvaluate)
    ->ArgsProduct({{0, 1}, {0, 1}})
    ->ArgNames({"jacobians", "bicubic"});

void BM_PhotometricEvaluateHuber(benchmark::State& state) {
  const Scene& scene = GetScene();
  const ceres::HuberLoss huber(1.345);
  const PhotometricResidual cost(scene.pyramid, 0, scene.camera, scene.photometric, &huber,
                                 InterpolationArg(state, 1));
  RunEvaluate(state, cost);
}
BENCHMARK(BM_PhotometricEvaluateHuber)
    ->ArgsProduct({{1}, {0, 1}})
    ->ArgNames({"jacobians", "bicubic"});

void BM_PhotometricEvaluateTangent(benchmark::State& state) {
  const Scene& scene = GetScene();
  const PhotometricResidual cost(scene.pyramid, 0, scene.camera, scene.photometric, nullptr,
                                 InterpolationArg(state, 0));
  std::vector<double> residuals(kBatch), jacobian(kBatch * 6);
  std::vector<std::uint8_t> valid(kBatch);
  for (auto _ : state) {
    cost.EvaluateTangent(scene.cur_from_ref, residuals.data(), jacobian.data(), valid.data());
    benchmark::DoNotOptimize(jacobian.data());
  }
  state.SetItemsProcessed(state.iterations() * kBatch);
}
BENCHMARK(BM_PhotometricEvaluateTangent)->Arg(0)->Arg(1)->ArgName("bicubic");

void BM_PointToLineEvaluate(benchmark::State& state) {
  const Scene& scene = GetScene();
  const PointToLineResidual cost(scene.camera, scene.lines);
  RunEvaluate(state, cost);
}
BENCHMARK(BM_PointToLineEvaluate)->Arg(0)->Arg(1)->ArgName("jacobians");

}  // namespace
}  // namespace pldvo

BENCHMARK_MAIN();
