// The parts of one mapping job (docs/odometry.md, Table III "mapping") on a synthetic `textured`
// 640x480 keyframe with its ground-truth edges, a map warmed up by 7 frames with ground-truth
// poses and line matches (frames 2, 4, ..., 14; the library's default MappingOptions):
//   Mapping/update           the stereo + EKF update with frame 16 (DepthMapper::UpdateWithFrame),
//                            num_threads:1 on the calling thread, :0 the default (all cores)
//   Mapping/regularized/...  RegularizedMap: smoothing (smooth:1) and 3D line regularisation
//                            (lines:1), what every job publishes
//   Mapping/reference        BuildReferencePoints of the published map (4000 points per level)
//   Mapping/propagate        PropagateDepthMap of the published map to frame 16 as a new
//                            keyframe (its ground-truth pose), what a keyframe switch runs
// and the regularisation steps (backend/mapping/depth_regularizer.h) on a generated 640x480
// semi-dense map (MakeEdgeMap: ~12% valid pixels in 3-px bands along random segments, variances
// log-uniform over four orders of magnitude, depth discontinuities where segments cross):
//   Mapping/smooth           SmoothDepthMap, what RegularizedMap(true, ...) runs
//   Mapping/remove_isolated  RemoveIsolatedHypotheses  } both after every UpdateWithFrame
//   Mapping/fill_holes       FillHoles                 }
// Run: build/experiments/benchmarks/mapping_benchmark [--benchmark_filter=...]
#include <benchmark/benchmark.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>
#include <vector>

#include "backend/mapping/depth_mapper.h"
#include "backend/mapping/depth_propagation.h"
#include "backend/mapping/depth_regularizer.h"
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
  // The same with options.num_threads = 1 (the stereo pass on the calling thread alone).
  DepthMapper one_thread_mapper;
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
    MappingOptions one_thread = options;
    one_thread.num_threads = 1;
    auto* f = new Fixture{sequence.camera,
                          options,
                          DepthMapper(sequence.camera, options),
                          DepthMapper(sequence.camera, one_thread),
                          {},
                          {},
                          {},
                          {}};
    f->mapper.InitializeKeyframe(keyframe.image, edges.trace);
    f->one_thread_mapper.InitializeKeyframe(keyframe.image, edges.trace);
    for (int k = 1; k <= kWarmupFrames + 1; ++k) {
      const int index = kKeyframe + k * kStride;
      const cv::Mat image = synthetic::RenderFrame(sequence, index).image;
      const SE3 cur_from_ref =
          sequence.ground_truth[index].world_from_cam.Inverse() * world_from_ref;
      const std::vector<MatchedLine> lines =
          ProjectGroundTruthLines(edges, sequence.camera, cur_from_ref, 0.25, 17 + k);
      if (k <= kWarmupFrames) {
        f->mapper.UpdateWithFrame(image, cur_from_ref, lines);
        f->one_thread_mapper.UpdateWithFrame(image, cur_from_ref, lines);
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
  const DepthMapper& warmed = state.range(0) == 1 ? fixture.one_thread_mapper : fixture.mapper;
  // Copy-assigned before every update (not timed) into the same object, whose buffers keep their
  // capacity: a fresh copy would make the update's own allocations land on freshly mapped pages.
  DepthMapper mapper = warmed;
  for (auto _ : state) {
    state.PauseTiming();
    mapper = warmed;
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

void BM_Propagate(benchmark::State& state) {
  const Fixture& fixture = GetFixture();
  const ImagePyramid new_keyframe(fixture.next_image, 1);
  PropagationStats stats;
  for (auto _ : state) {
    SemiDenseDepthMap map =
        PropagateDepthMap(fixture.published, fixture.mapper.keyframe(), new_keyframe, cv::Mat(),
                          fixture.camera, fixture.next_from_ref, fixture.options, &stats);
    benchmark::DoNotOptimize(map);
  }
  state.counters["propagated"] = stats.propagated;
}

// The generated map of the regularisation benchmarks: 65 random segments of 40-300 px drawn
// 3 px wide (a later segment overwrites an earlier one where they cross); each band pixel at
// least 4 px from the border is a candidate, 90% of them valid with a per-segment plane of
// inverse depth plus noise and a variance log-uniform in [1e-5, 1e-1] (1/m)^2, 3% of the others
// blacklisted.
SemiDenseDepthMap MakeEdgeMap(const MappingOptions& options) {
  constexpr int kWidth = 640, kHeight = 480, kSegments = 65, kBorder = 4;
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  cv::Mat edge_id(kHeight, kWidth, CV_32S, cv::Scalar(-1));
  for (int s = 0; s < kSegments; ++s) {
    const cv::Point a(static_cast<int>(unit(rng) * kWidth), static_cast<int>(unit(rng) * kHeight));
    const double angle = 2.0 * M_PI * unit(rng), length = 40.0 + 260.0 * unit(rng);
    const cv::Point b(a.x + static_cast<int>(length * std::cos(angle)),
                      a.y + static_cast<int>(length * std::sin(angle)));
    cv::line(edge_id, a, b, cv::Scalar(s), 3, cv::LINE_8);
  }
  std::vector<double> base(kSegments), slope_x(kSegments), slope_y(kSegments);
  for (int s = 0; s < kSegments; ++s) {
    base[s] = 0.1 + 1.9 * unit(rng);
    slope_x[s] = 1e-3 * (unit(rng) - 0.5);
    slope_y[s] = 1e-3 * (unit(rng) - 0.5);
  }
  std::normal_distribution<double> noise(0.0, 0.01);
  SemiDenseDepthMap map(kWidth, kHeight);
  for (int y = kBorder; y < kHeight - kBorder; ++y) {
    for (int x = kBorder; x < kWidth - kBorder; ++x) {
      const int s = edge_id.at<int>(y, x);
      if (s < 0) continue;
      const int i = map.Index(x, y);
      map.SetCandidate(i, true, s);
      if (unit(rng) < 0.9) {
        const double idepth = base[s] + slope_x[s] * x + slope_y[s] * y + noise(rng);
        map.Set(i, idepth, std::pow(10.0, -5.0 + 4.0 * unit(rng)), options.validity_initial);
      } else if (unit(rng) < 0.03) {
        for (int k = 0; k < options.blacklist_threshold; ++k) map.AddBlacklist(i);
      }
    }
  }
  return map;
}

const SemiDenseDepthMap& GetEdgeMap() {
  static const SemiDenseDepthMap* map = new SemiDenseDepthMap(MakeEdgeMap(MappingOptions()));
  return *map;
}

void BM_Smooth(benchmark::State& state) {
  const SemiDenseDepthMap& map = GetEdgeMap();
  const MappingOptions options;
  SemiDenseDepthMap out;
  int smoothed = 0;
  for (auto _ : state) {
    smoothed = SmoothDepthMap(map, options, &out);
    benchmark::DoNotOptimize(out);
  }
  state.counters["valid"] = map.CountValid();
  state.counters["smoothed"] = smoothed;
}

// The in-place steps run on a copy of the map, assigned before every call (not timed) into the
// same object so that its buffers keep their capacity.
template <int (*kStep)(const MappingOptions&, SemiDenseDepthMap*)>
void BM_InPlaceStep(benchmark::State& state) {
  const SemiDenseDepthMap& map = GetEdgeMap();
  const MappingOptions options;
  SemiDenseDepthMap work = map;
  int changed = 0;
  for (auto _ : state) {
    state.PauseTiming();
    work = map;
    state.ResumeTiming();
    changed = kStep(options, &work);
    benchmark::DoNotOptimize(work);
  }
  state.counters["valid"] = map.CountValid();
  state.counters["changed"] = changed;
}

BENCHMARK(BM_Update)
    ->Name("Mapping/update")
    ->ArgName("num_threads")
    ->Arg(1)
    ->Arg(0)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
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
BENCHMARK(BM_Propagate)->Name("Mapping/propagate")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Smooth)->Name("Mapping/smooth")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_InPlaceStep<RemoveIsolatedHypotheses>)
    ->Name("Mapping/remove_isolated")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_InPlaceStep<FillHoles>)
    ->Name("Mapping/fill_holes")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace pldvo

BENCHMARK_MAIN();
