// The parts of one mapping job (docs/odometry.md, Table III "mapping") on a synthetic `textured`
// 640x480 keyframe with its ground-truth edges, a map warmed up by 7 frames with ground-truth
// poses and line matches (frames 2, 4, ..., 14; the library's default MappingOptions):
//   Mapping/update           the stereo + EKF update with frame 16 (DepthMapper::UpdateWithFrame)
//   Mapping/regularized/...  RegularizedMap: smoothing (smooth:1) and 3D line regularisation
//                            (lines:1), what every job publishes
//   Mapping/reference        BuildReferencePoints of the published map (4000 points per level)
// Run: build/experiments/benchmarks/mapping_benchmark [--benchmark_filter=...]
#include <benchmark/benchmark.h>

#include <vector>

#include "backend/mapping/depth_mapper.h"
#include "backend/odometry/reference_builder.h"
#include "experiments/evaluation/mapping_ground_truth.h"
#include "experiments/evaluation/synthetic_pairs.h"

namespace pldvo {
namespace {

constexpr int kKeyframe = 0, kStride = 2, kWarmupFrames = 7;

struct Fixture {
  PinholeCamera camera;
  MappingOptions options;
  DepthMapper mapper;  // after the warm-up frames
  cv::Mat next_image;  // frame 16
  SE3 next_from_ref;
  std::vector<MatchedLine> next_lines;
  SemiDenseDepthMap published;  // RegularizedMap(true, true) of `mapper`
};

const Fixture& GetFixture() {
  static const Fixture* fixture = [] {
    const synthetic::SyntheticSequence sequence = synthetic_pairs::MakeScaledSequence(
        "textured", kKeyframe + (kWarmupFrames + 1) * kStride + 1, 1, 640, 480);
    const synthetic::RenderedFrame keyframe = synthetic::RenderFrame(sequence, kKeyframe);
    const SE3& world_from_ref = sequence.ground_truth[kKeyframe].world_from_cam;
    const GroundTruthEdges edges = MakeGroundTruthEdges(
        synthetic_pairs::SegmentsInCam(sequence.scene, world_from_ref.Inverse()), keyframe.depth,
        sequence.camera, GroundTruthEdgeOptions());
    const MappingOptions options;
    auto* f = new Fixture{
        sequence.camera, options, DepthMapper(sequence.camera, options), {}, {}, {}, {}};
    f->mapper.InitializeKeyframe(keyframe.image, edges.trace);
    for (int k = 1; k <= kWarmupFrames + 1; ++k) {
      const int index = kKeyframe + k * kStride;
      const cv::Mat image = synthetic::RenderFrame(sequence, index).image;
      const SE3 cur_from_ref =
          sequence.ground_truth[index].world_from_cam.Inverse() * world_from_ref;
      const std::vector<MatchedLine> lines =
          ProjectGroundTruthLines(edges, sequence.camera, cur_from_ref, 0.25, 17 + k);
      if (k <= kWarmupFrames) {
        f->mapper.UpdateWithFrame(image, cur_from_ref, lines);
      } else {
        f->next_image = image;
        f->next_from_ref = cur_from_ref;
        f->next_lines = lines;
      }
    }
    f->published = f->mapper.RegularizedMap(true, true);
    return f;
  }();
  return *fixture;
}

void BM_Update(benchmark::State& state) {
  const Fixture& fixture = GetFixture();
  FrameUpdateStats stats;
  // Copy-assigned before every update (not timed) into the same object, whose buffers keep their
  // capacity: a fresh copy would make the update's own allocations land on freshly mapped pages.
  DepthMapper mapper = fixture.mapper;
  for (auto _ : state) {
    state.PauseTiming();
    mapper = fixture.mapper;
    state.ResumeTiming();
    stats = mapper.UpdateWithFrame(fixture.next_image, fixture.next_from_ref, fixture.next_lines);
    benchmark::DoNotOptimize(stats);
  }
  state.counters["edge_pixels"] = stats.num_edge_pixels;
  state.counters["line_ok"] = stats.line_ok;
  state.counters["ssd_ok"] = stats.ssd_ok;
}

void BM_Regularized(benchmark::State& state) {
  const Fixture& fixture = GetFixture();
  const bool smooth = state.range(0) != 0, lines = state.range(1) != 0;
  for (auto _ : state) {
    SemiDenseDepthMap map = fixture.mapper.RegularizedMap(smooth, lines);
    benchmark::DoNotOptimize(map);
  }
  state.counters["valid"] = fixture.published.CountValid();
}

void BM_Reference(benchmark::State& state) {
  const Fixture& fixture = GetFixture();
  TrackingReference reference;
  for (auto _ : state) {
    reference = BuildReferencePoints(fixture.published, fixture.mapper.keyframe(), fixture.camera,
                                     fixture.options.max_reference_points, {});
    benchmark::DoNotOptimize(reference);
  }
  state.counters["points_level0"] = reference.levels[0].points.size();
}

BENCHMARK(BM_Update)->Name("Mapping/update")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Regularized)
    ->Name("Mapping/regularized")
    ->ArgNames({"smooth", "lines"})
    ->Args({0, 0})
    ->Args({1, 0})
    ->Args({0, 1})
    ->Args({1, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_Reference)->Name("Mapping/reference")->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace pldvo

BENCHMARK_MAIN();
