// Line frontend components (seed paper Sec. VI-A(1), Table III) at 640x480 on synthetic
// `lowtex` frames (seed 1, frames 0 and 5):
//   Detect/<lsd|edlines>      8-bit conversion, two-octave pyramid and detection (unmerged)
//   Merge                     bucket-grid merging + length filter of the default (EDLines)
//                             detections
//   Describe                  LBD of the merged default lines
//   Match                     frame 0 -> frame 5 bucketed matching (no predictor)
//   Process/<lsd|edlines>     the whole per-frame pipeline (detect + merge + describe)
//   Textured/<variant>        the whole pipeline on a `textured` frame (seed 3, frame 0; the
//                             costliest frames of Table III), with the detect / merge /
//                             describe milliseconds as counters: the defaults and the options
//                             that trade accuracy for time (docs/line_frontend.md)
// and, when /work/shared/data/kitti00_first200 exists (skipped otherwise), the whole frontend
// over its 200 frames (1241x376): Kitti/<lsd|edlines> processes one frame per iteration and
// matches it to the previous one; counters report lines (edges) per frame, detections per
// frame, matches and the milliseconds per component (LineFrontendTiming).
// Run: build/experiments/benchmarks/line_frontend_benchmark [--benchmark_filter=...]
#include <benchmark/benchmark.h>

#include <algorithm>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <utility>
#include <vector>

#include "experiments/synthetic/synthetic_sequence.h"
#include "frontend/line_frontend.h"

namespace pldvo {
namespace {

constexpr char kKittiDir[] = "/work/shared/data/kitti00_first200";

struct SyntheticFixture {
  cv::Mat image0, image5;              // CV_8U 640x480
  std::vector<LineSegment> detected0;  // default detector (EDLines), unmerged
  LineFrame frame0, frame5;            // default options, every segment described
};

const SyntheticFixture& GetSyntheticFixture() {
  static const SyntheticFixture fixture = [] {
    synthetic::SynthOptions options;
    options.preset = "lowtex";
    options.frames = 6;
    options.seed = 1;
    const synthetic::SyntheticSequence sequence = synthetic::MakeSequence(options);
    SyntheticFixture f;
    f.image0 = synthetic::RenderFrame(sequence, 0).image;
    f.image5 = synthetic::RenderFrame(sequence, 5).image;
    const LineFrontendOptions defaults;
    LineDetector detector(defaults.detector);
    f.detected0 = detector.Detect(
        BuildOctaves(f.image0, defaults.detector.first_octave + defaults.detector.num_octaves));
    LineFrontendOptions described = defaults;
    described.descriptor.on_demand = false;
    LineFrontend frontend(described);
    f.frame0 = frontend.Process(f.image0);
    f.frame5 = frontend.Process(f.image5);
    return f;
  }();
  return fixture;
}

LineFrontendOptions OptionsFor(LineDetectorOptions::Method method) {
  LineFrontendOptions options;
  options.detector.method = method;
  return options;
}

void BM_Detect(benchmark::State& state, LineDetectorOptions::Method method) {
  const SyntheticFixture& fixture = GetSyntheticFixture();
  const LineDetectorOptions options = OptionsFor(method).detector;
  LineDetector detector(options);
  size_t num_segments = 0;
  for (auto _ : state) {
    const std::vector<cv::Mat> octaves =
        BuildOctaves(ToGray8(fixture.image0), options.first_octave + options.num_octaves);
    const std::vector<LineSegment> segments = detector.Detect(octaves);
    num_segments = segments.size();
    benchmark::DoNotOptimize(segments.data());
  }
  state.counters["segments"] = static_cast<double>(num_segments);
}

void BM_Merge(benchmark::State& state) {
  const SyntheticFixture& fixture = GetSyntheticFixture();
  const LineFrontendOptions options;
  const LineMerger merger(options.merger, options.detector.endpoint_sigma_px);
  size_t num_lines = 0;
  for (auto _ : state) {
    const std::vector<LineSegment> merged = merger.Merge(fixture.detected0);
    num_lines = merged.size();
    benchmark::DoNotOptimize(merged.data());
  }
  state.counters["segments_in"] = static_cast<double>(fixture.detected0.size());
  state.counters["lines"] = static_cast<double>(num_lines);
}

void BM_Describe(benchmark::State& state) {
  const SyntheticFixture& fixture = GetSyntheticFixture();
  LbdDescriber describer{LineDescriptorOptions()};
  for (auto _ : state) {
    const cv::Mat descriptors = describer.Describe(fixture.image0, fixture.frame0.segments);
    benchmark::DoNotOptimize(descriptors.data);
  }
  state.counters["lines"] = static_cast<double>(fixture.frame0.segments.size());
}

void BM_Match(benchmark::State& state) {
  const SyntheticFixture& fixture = GetSyntheticFixture();
  const LineMatcher matcher{LineMatcherOptions()};
  size_t num_matches = 0;
  for (auto _ : state) {
    const std::vector<LineMatch> matches =
        matcher.Match(fixture.frame0.segments, fixture.frame0.descriptors, fixture.frame5.segments,
                      fixture.frame5.descriptors);
    num_matches = matches.size();
    benchmark::DoNotOptimize(matches.data());
  }
  state.counters["lines"] = static_cast<double>(fixture.frame0.segments.size());
  state.counters["matches"] = static_cast<double>(num_matches);
}

void BM_Process(benchmark::State& state, LineDetectorOptions::Method method) {
  const SyntheticFixture& fixture = GetSyntheticFixture();
  LineFrontendOptions options = OptionsFor(method);
  options.descriptor.on_demand = false;  // the whole per-frame cost
  LineFrontend frontend(options);
  size_t num_lines = 0;
  for (auto _ : state) {
    const LineFrame frame = frontend.Process(fixture.image0);
    num_lines = frame.segments.size();
    benchmark::DoNotOptimize(frame.descriptors.data);
  }
  state.counters["lines"] = static_cast<double>(num_lines);
}

const cv::Mat& TexturedFrame() {
  static const cv::Mat image = [] {
    synthetic::SynthOptions options;
    options.preset = "textured";
    options.frames = 1;
    options.seed = 3;
    return synthetic::RenderFrame(synthetic::MakeSequence(options), 0).image;
  }();
  return image;
}

void BM_Textured(benchmark::State& state, LineFrontendOptions options) {
  const cv::Mat& image = TexturedFrame();
  options.descriptor.on_demand = false;  // the whole per-frame cost
  LineFrontend frontend(options);
  LineFrontendTiming sum;
  int64_t num_frames = 0;
  for (auto _ : state) {
    const LineFrame frame = frontend.Process(image);
    sum.detection_ms += frame.timing.detection_ms;
    sum.merging_ms += frame.timing.merging_ms;
    sum.description_ms += frame.timing.description_ms;
    sum.num_detected = frame.timing.num_detected;
    sum.num_lines = frame.timing.num_lines;
    ++num_frames;
  }
  const double n = static_cast<double>(std::max<int64_t>(1, num_frames));
  state.counters["detected"] = sum.num_detected;
  state.counters["lines"] = sum.num_lines;
  state.counters["detect_ms"] = sum.detection_ms / n;
  state.counters["merge_ms"] = sum.merging_ms / n;
  state.counters["describe_ms"] = sum.description_ms / n;
}

// The KITTI frames in file-name order, 8-bit gray; empty when the folder is missing.
const std::vector<cv::Mat>& KittiFrames() {
  static const std::vector<cv::Mat> frames = [] {
    std::vector<cv::Mat> images;
    const std::filesystem::path dir = std::filesystem::path(kKittiDir) / "rgb";
    if (!std::filesystem::is_directory(dir)) return images;
    std::vector<std::filesystem::path> paths;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
      if (entry.path().extension() == ".png") paths.push_back(entry.path());
    }
    std::sort(paths.begin(), paths.end());
    for (const auto& path : paths) {
      cv::Mat image = cv::imread(path.string(), cv::IMREAD_GRAYSCALE);
      if (image.empty())
        throw std::runtime_error("line_frontend_benchmark: cannot read " + path.string());
      images.push_back(image);
    }
    return images;
  }();
  return frames;
}

// Frame-to-frame matching as the odometry does it (descriptions on demand unless `options` says
// otherwise).
void BM_Kitti(benchmark::State& state, const LineFrontendOptions& options) {
  const std::vector<cv::Mat>& frames = KittiFrames();
  LineFrontend frontend(options);
  LineFrame previous = frontend.Process(frames[0]);
  size_t index = 1;
  LineFrontendTiming sum;
  int64_t num_frames = 0;
  for (auto _ : state) {
    LineFrame frame = frontend.Process(frames[index]);
    LineFrontendTiming timing = frame.timing;
    frontend.Match(&previous, &frame, nullptr, &timing);
    sum.detection_ms += timing.detection_ms;
    sum.merging_ms += timing.merging_ms;
    sum.description_ms += timing.description_ms;
    sum.matching_ms += timing.matching_ms;
    sum.num_detected += timing.num_detected;
    sum.num_lines += timing.num_lines;
    sum.num_matches += timing.num_matches;
    ++num_frames;
    previous = std::move(frame);
    index = index + 1 < frames.size() ? index + 1 : 1;
    if (index == 1) previous = frontend.Process(frames[0]);  // restart the sequence
  }
  const double n = static_cast<double>(std::max<int64_t>(1, num_frames));
  state.counters["edges_per_frame"] = sum.num_lines / n;
  state.counters["detected_per_frame"] = sum.num_detected / n;
  state.counters["matches_per_frame"] = sum.num_matches / n;
  state.counters["detect_ms"] = sum.detection_ms / n;
  state.counters["merge_ms"] = sum.merging_ms / n;
  state.counters["describe_ms"] = sum.description_ms / n;
  state.counters["match_ms"] = sum.matching_ms / n;
  state.counters["frames"] = static_cast<double>(frames.size());
}

void RegisterAll() {
  using Method = LineDetectorOptions::Method;
  benchmark::RegisterBenchmark("Detect/lsd", BM_Detect, Method::kLsd)
      ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("Detect/edlines", BM_Detect, Method::kEdLines)
      ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("Merge", BM_Merge)->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("Describe", BM_Describe)->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("Match", BM_Match)->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("Process/lsd", BM_Process, Method::kLsd)
      ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("Process/edlines", BM_Process, Method::kEdLines)
      ->Unit(benchmark::kMillisecond);
  const LineFrontendOptions defaults;
  LineFrontendOptions one_octave = defaults;
  one_octave.detector.num_octaves = 1;
  LineFrontendOptions coarse_lbd = defaults;
  coarse_lbd.descriptor.min_octave = 2;
  LineFrontendOptions fewer_lines = defaults;
  fewer_lines.merger.max_segments = 100;
  LineFrontendOptions no_nfa = defaults;
  no_nfa.detector.edlines_nfa_validation = false;
  LineFrontendOptions short_support = defaults;
  short_support.descriptor.max_support_px = 32;
  LineFrontendOptions refit = defaults;
  refit.refiner.enabled = true;
  for (const auto& [name, options] :
       {std::pair<const char*, LineFrontendOptions>{"Textured/default", defaults},
        {"Textured/num_octaves:1", one_octave},
        {"Textured/descriptor_min_octave:2", coarse_lbd},
        {"Textured/max_segments:100", fewer_lines},
        {"Textured/edlines_nfa_validation:0", no_nfa},
        {"Textured/descriptor_max_support:32", short_support},
        {"Textured/refiner:1", refit}}) {
    benchmark::RegisterBenchmark(name, BM_Textured, options)->Unit(benchmark::kMillisecond);
  }
  if (std::filesystem::is_directory(std::filesystem::path(kKittiDir) / "rgb")) {
    // One pass over the sequence (199 processed + matched frames) per variant.
    LineFrontendOptions describe_all = defaults;
    describe_all.descriptor.on_demand = false;
    for (const auto& [name, options] :
         {std::pair<const char*, LineFrontendOptions>{"Kitti/lsd", OptionsFor(Method::kLsd)},
          {"Kitti/edlines", OptionsFor(Method::kEdLines)},
          {"Kitti/edlines_describe_all", describe_all}}) {
      benchmark::RegisterBenchmark(name, BM_Kitti, options)
          ->Unit(benchmark::kMillisecond)
          ->Iterations(199);
    }
  }
}

}  // namespace
}  // namespace pldvo

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  pldvo::RegisterAll();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
