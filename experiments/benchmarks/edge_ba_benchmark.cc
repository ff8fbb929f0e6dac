// Time per window of windowed edge bundle adjustment (docs/edge_ba.md, "Measurements"):
// build + solve of one window of 3, 5 or 7 keyframes observing 150 simulated lines (3-6 m away,
// keyframes 30 cm apart, 24 edge pixels per observation of which 16 are used, 0.5 px noise,
// initial poses off by 2 cm / 0.5 deg, lines triangulated), default EdgeBAOptions except the
// arguments: 10, 20 or 30 LM iterations, Huber per pixel or batched or no loss, and each
// linear solver.
//   build/experiments/benchmarks/edge_ba_benchmark
// Counters: lines, pixel residuals, LM iterations, ms per iteration, and RMSE of the non-fixed
// camera centres before / after (mm).
#include <benchmark/benchmark.h>

#include <vector>

#include "backend/edge_ba/edge_ba_solver.h"
#include "experiments/evaluation/edge_ba_simulation.h"

namespace pldvo {
namespace {

EdgeBASimulation MakeWindow(int num_keyframes) {
  const EdgeBAScene scene = MakeRandomLineScene(150, num_keyframes, 0.3, 5);
  const PinholeCamera camera{640, 480, 525.0, 525.0, 319.5, 239.5};
  EdgeBASimulationOptions options;
  options.provide_initial_lines = false;
  options.seed = 6;
  return SimulateEdgeBAWindow(camera, scene.world_from_cam, scene.start, scene.end, options);
}

void BM_EdgeBAWindow(benchmark::State& state) {
  const int num_keyframes = static_cast<int>(state.range(0));
  const EdgeBASimulation simulation = MakeWindow(num_keyframes);
  EdgeBAOptions options;
  options.enabled = true;
  options.window = num_keyframes;
  options.linear_solver = static_cast<EdgeBALinearSolver>(state.range(1));
  options.max_iterations = static_cast<int>(state.range(2));
  options.robust_loss = static_cast<RobustLossKind>(state.range(3));
  options.batch_pixels = state.range(4) != 0;
  EdgeBAResult result;
  for (auto _ : state) {
    result = SolveEdgeBA(simulation.window, options);
    benchmark::DoNotOptimize(result);
  }
  std::vector<EdgeBAResultKeyframe> initial;
  for (const EdgeBAKeyframe& keyframe : simulation.window.keyframes) {
    initial.push_back({keyframe.id, keyframe.cam_from_world, false});
  }
  std::vector<EdgeBALine> lines;
  for (const EdgeBAResultLine& line : result.lines) lines.push_back(line.line);
  state.counters["lines"] = result.num_optimized_lines;
  state.counters["residuals"] = result.num_residuals;
  state.counters["iterations"] = result.iterations;
  state.counters["ms_per_iteration"] = 1e3 * result.solve_seconds / std::max(1, result.iterations);
  state.counters["build_ms"] = 1e3 * result.build_seconds;
  state.counters["pos_before_mm"] =
      1e3 * ComputeEdgeBAErrors(simulation, initial, {}).position_rmse_m;
  state.counters["pos_after_mm"] =
      1e3 * ComputeEdgeBAErrors(simulation, result.keyframes, lines).position_rmse_m;
  state.SetLabel(result.success ? BALinearSolverNames()[state.range(1)].first + " " +
                                      RobustLossKindNames()[state.range(3)].first +
                                      (options.batch_pixels ? " batched" : " per-pixel")
                                : "FAILED");
}

// Args: keyframes, linear solver, max LM iterations, robust loss, batch_pixels.
constexpr int kSparseSchur = static_cast<int>(EdgeBALinearSolver::kSparseSchur);
constexpr int kDenseSchur = static_cast<int>(EdgeBALinearSolver::kDenseSchur);
constexpr int kSparseNormal = static_cast<int>(EdgeBALinearSolver::kSparseNormalCholesky);
constexpr int kHuber = static_cast<int>(RobustLossKind::kHuber);
constexpr int kNoLoss = static_cast<int>(RobustLossKind::kNone);
// Iteration budgets with the robust loss per pixel (default) and batched, and without a loss.
BENCHMARK(BM_EdgeBAWindow)
    ->ArgsProduct({{3, 5, 7}, {kSparseSchur}, {10, 20, 30}, {kHuber}, {0, 1}})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_EdgeBAWindow)
    ->ArgsProduct({{3, 5, 7}, {kSparseSchur}, {20}, {kNoLoss}, {1}})
    ->Unit(benchmark::kMillisecond);
// Linear-solver ablation at the default budget.
BENCHMARK(BM_EdgeBAWindow)
    ->ArgsProduct({{3, 5, 7}, {kDenseSchur, kSparseNormal}, {20}, {kHuber}, {0}})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace pldvo

BENCHMARK_MAIN();
