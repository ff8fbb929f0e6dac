// One full coarse-to-fine tracking solve (4 levels, points and lines, covariance weights) of a
// synthetic `lowtex` 640x480 frame pair (frames 10 -> 14, GT depth reference with GT line
// matches), from the identity pose, per solver, residual layout and photometric interpolation:
//   Track/<solver>/<builder>/batch:<N>[/<ceres linear solver>/threads:<T>][/bicubic]
//   [/shared_line_error] (line_error_model shared_per_edge: one block per edge)
//   [/affine] (brightness affine: the pose and {a, b}, residuals/affine_brightness.h)
// (no suffix: bilinear, the default).
// The time includes building each level's problem (weights, cost functions) and solving it.
// Run: build/experiments/benchmarks/tracking_benchmark [--benchmark_filter=...]
#include <benchmark/benchmark.h>

#include <memory>
#include <string>

#include "backend/tracking/tracker.h"
#include "experiments/evaluation/synthetic_pairs.h"

namespace pldvo {
namespace {

struct Fixture {
  synthetic_pairs::FramePair pair;
  TrackingReference reference;
  ImagePyramid current;
};

const Fixture& GetFixture() {
  static const Fixture fixture = [] {
    Fixture f;
    const synthetic::SyntheticSequence sequence =
        synthetic_pairs::MakeScaledSequence("lowtex", 20, 1, 640, 480);
    f.pair = synthetic_pairs::MakeFramePair(sequence, 10, 14);
    f.reference = synthetic_pairs::MakePairReference(f.pair, GroundTruthReferenceOptions(), true);
    f.current = ImagePyramid(f.pair.cur_image, 4);
    return f;
  }();
  return fixture;
}

void BM_Track(benchmark::State& state, TrackingOptions options) {
  const Fixture& fixture = GetFixture();
  const Tracker tracker(options);
  TrackingResult result;
  for (auto _ : state) {
    result = tracker.Track(fixture.reference, fixture.current, SE3());
    benchmark::DoNotOptimize(result);
  }
  state.counters["iterations"] = result.TotalIterations();
  for (const LevelResult& level : result.levels) {
    state.counters["it_L" + std::to_string(level.level)] = level.iterations;
  }
  state.counters["rows_level0"] = result.levels.back().residual_rows;
  state.counters["error_mm"] =
      1e3 * synthetic_pairs::TranslationError(result.cur_from_ref, fixture.pair.cur_from_ref);
}

void RegisterAll() {
  struct Variant {
    SolverOptions::Type solver;
    std::string builder;
    int batch;
    SolverOptions::CeresLinearSolver linear;
    int threads;
    ImageInterpolation interpolation = ImageInterpolation::kBilinear;
    LineErrorModel line_error_model = LineErrorModel::kPerPixel;
    BrightnessModel brightness = BrightnessModel::kNone;
  };
  using LS = SolverOptions::CeresLinearSolver;
  const Variant variants[] = {
      {SolverOptions::Type::kGaussNewton, "tracking", 1, LS::kDenseNormalCholesky, 1},
      {SolverOptions::Type::kGaussNewton, "tracking", 16, LS::kDenseNormalCholesky, 1},
      {SolverOptions::Type::kGaussNewton, "tracking", 128, LS::kDenseNormalCholesky, 1},
      {SolverOptions::Type::kGaussNewton, "tracking", 1024, LS::kDenseNormalCholesky, 1},
      {SolverOptions::Type::kGaussNewton, "tracking_ceres_loss", 1, LS::kDenseNormalCholesky, 1},
      {SolverOptions::Type::kCeres, "tracking", 1, LS::kDenseNormalCholesky, 1},
      {SolverOptions::Type::kCeres, "tracking", 16, LS::kDenseNormalCholesky, 1},
      {SolverOptions::Type::kCeres, "tracking", 128, LS::kDenseNormalCholesky, 1},
      {SolverOptions::Type::kCeres, "tracking", 1024, LS::kDenseNormalCholesky, 1},
      {SolverOptions::Type::kCeres, "tracking_ceres_loss", 1, LS::kDenseNormalCholesky, 1},
      {SolverOptions::Type::kCeres, "tracking", 128, LS::kDenseQr, 1},
      {SolverOptions::Type::kCeres, "tracking", 128, LS::kDenseNormalCholesky, 2},
      {SolverOptions::Type::kCeres, "tracking", 128, LS::kDenseQr, 2},
      {SolverOptions::Type::kGaussNewton, "tracking", 1, LS::kDenseNormalCholesky, 1,
       ImageInterpolation::kBicubic},
      {SolverOptions::Type::kGaussNewton, "tracking", 128, LS::kDenseNormalCholesky, 1,
       ImageInterpolation::kBicubic},
      {SolverOptions::Type::kCeres, "tracking", 1, LS::kDenseNormalCholesky, 1,
       ImageInterpolation::kBicubic},
      {SolverOptions::Type::kCeres, "tracking", 128, LS::kDenseNormalCholesky, 1,
       ImageInterpolation::kBicubic},
      {SolverOptions::Type::kGaussNewton, "tracking", 128, LS::kDenseNormalCholesky, 1,
       ImageInterpolation::kBilinear, LineErrorModel::kSharedPerEdge},
      {SolverOptions::Type::kCeres, "tracking", 128, LS::kDenseNormalCholesky, 1,
       ImageInterpolation::kBilinear, LineErrorModel::kSharedPerEdge},
      {SolverOptions::Type::kGaussNewton, "tracking", 128, LS::kDenseNormalCholesky, 1,
       ImageInterpolation::kBilinear, LineErrorModel::kPerPixel, BrightnessModel::kAffine},
      {SolverOptions::Type::kCeres, "tracking", 128, LS::kDenseNormalCholesky, 1,
       ImageInterpolation::kBilinear, LineErrorModel::kPerPixel, BrightnessModel::kAffine},
  };
  for (const Variant& v : variants) {
    TrackingOptions options;
    options.solver.type = v.solver;
    options.solver.ceres_linear_solver = v.linear;
    options.solver.num_threads = v.threads;
    options.problem_builder = v.builder;
    options.problem.batch_size = v.batch;
    options.problem.interpolation = v.interpolation;
    options.problem.weighting.line_error_model = v.line_error_model;
    options.problem.brightness = v.brightness;
    options.record_edge_pixels = false;
    std::string name = std::string("Track/") +
                       (v.solver == SolverOptions::Type::kCeres ? "ceres" : "gauss_newton") + "/" +
                       v.builder + "/batch:" + std::to_string(v.batch);
    if (v.solver == SolverOptions::Type::kCeres) {
      name += std::string(v.linear == LS::kDenseQr ? "/dense_qr" : "/dense_normal_cholesky") +
              "/threads:" + std::to_string(v.threads);
    }
    if (v.interpolation == ImageInterpolation::kBicubic) name += "/bicubic";
    if (v.line_error_model == LineErrorModel::kSharedPerEdge) name += "/shared_line_error";
    if (v.brightness == BrightnessModel::kAffine) name += "/affine";
    benchmark::RegisterBenchmark(name.c_str(), BM_Track, options)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  }
}

}  // namespace
}  // namespace pldvo

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  pldvo::RegisterAll();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
