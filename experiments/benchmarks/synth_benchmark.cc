// Rendering speed of the synthetic sequence generator (experiments/synthetic/, docs/synthetic.md):
// one 640x480 frame per iteration, with the frame rate as the counter `fps`.
//   Render/<preset>/threads:<T>        RenderFrame (supersampling 4, noise), frame index cycling
//   Render/lowtex_blur5/threads:<T>    with 5-sample motion blur
//   Render/lowtex_nosupersampling/...  supersampling 1
// Run: build/experiments/benchmarks/synth_benchmark [--benchmark_filter=...]
#include <benchmark/benchmark.h>

#include <string>

#include "experiments/synthetic/synthetic_sequence.h"

namespace pldvo::synthetic {
namespace {

constexpr int kFrames = 60;

SynthOptions BenchmarkOptions(const std::string& preset, int threads) {
  SynthOptions options;
  options.preset = preset;
  options.frames = kFrames;
  options.width = 640;
  options.height = 480;
  options.threads = threads;
  return options;
}

void BM_Render(benchmark::State& state, const std::string& preset, bool motion_blur,
               int supersampling) {
  SynthOptions options = BenchmarkOptions(preset, static_cast<int>(state.range(0)));
  options.motion_blur = motion_blur;
  options.supersampling = supersampling;
  const SyntheticSequence sequence = MakeSequence(options);
  int index = 0;
  for (auto _ : state) {
    RenderedFrame frame = RenderFrame(sequence, index);
    benchmark::DoNotOptimize(frame.image.data);
    index = (index + 7) % kFrames;  // spread over the trajectory
  }
  state.counters["fps"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

// Trajectory search (MakeSequence: scene, path draws, clearance and visibility checks) for a
// 300-frame sequence; no rendering.
void BM_MakeSequence(benchmark::State& state) {
  SynthOptions options = BenchmarkOptions("lowtex", 1);
  options.frames = 300;
  for (auto _ : state) {
    SyntheticSequence sequence = MakeSequence(options);
    benchmark::DoNotOptimize(sequence.ground_truth.data());
  }
}

BENCHMARK_CAPTURE(BM_Render, textured, std::string("textured"), false, 4)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Render, lowtex, std::string("lowtex"), false, 4)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Render, lighting, std::string("lighting"), false, 4)
    ->ArgName("threads")
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Render, fast, std::string("fast"), false, 4)
    ->ArgName("threads")
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Render, lowtex_blur5, std::string("lowtex"), true, 4)
    ->ArgName("threads")
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Render, lowtex_nosupersampling, std::string("lowtex"), false, 1)
    ->ArgName("threads")
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_MakeSequence)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace pldvo::synthetic

BENCHMARK_MAIN();
