// Time per window of windowed photometric + line bundle adjustment (docs/windowed_ba.md,
// "Measurements"): build + solve of one window of the hand-made scene of
// experiments/evaluation/windowed_ba_simulation.h at 640x480 (f = 525), 5 keyframes 10 cm
// apart, poses off by 2.5 mm / 0.1 deg per axis and inverse depths by 2.5%, with the default
// WindowedBAOptions except the arguments: points per window (500, 2000) and the solver (ceres
// SPARSE_SCHUR, ceres DENSE_SCHUR, gauss_newton with Schur on the inverse depths).
//   build/experiments/benchmarks/windowed_ba_benchmark
// BM_WindowedBAPrior: the inverse-depth prior (idepth_prior_scale 0, 1, 10) and
// depth_variance_in_weights (1, 0) on the test's window (4 keyframes, 320x240, 800 points, 50
// iterations) for simulation seeds 1-5.
// Counters: points, photometric and line rows, iterations, build and solve ms, and the rotation
// / translation RMS (deg, mm, after fitting the scale) and median / RMS relative inverse-depth
// error before and after.
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "backend/windowed_ba/windowed_ba_solver.h"
#include "experiments/evaluation/windowed_ba_simulation.h"

namespace pldvo {
namespace {

const WindowedBASimulation& Window() {
  static const WindowedBASimulation simulation = [] {
    WindowedBASimulationOptions options;
    options.width = 640;
    options.height = 480;
    options.focal = 525.0;
    options.num_keyframes = 5;
    return SimulateWindowedBAWindow(options);
  }();
  return simulation;
}

// state.range(0): points per window; state.range(1): 0 ceres sparse_schur, 1 ceres dense_schur,
// 2 gauss_newton.
void SetCounters(const WindowedBASimulation& simulation, const WindowedBAResult& result,
                 benchmark::State* state) {
  std::vector<SE3> poses;
  for (const WindowedBAResultKeyframe& keyframe : result.keyframes) {
    poses.push_back(keyframe.cam_from_world);
  }
  const WindowedBAErrors before = EvaluateWindowedBAInput(simulation, result.points);
  const WindowedBAErrors after = EvaluateWindowedBA(simulation, poses, result.points);
  state->counters["points"] = static_cast<double>(result.points.size());
  state->counters["photometric_rows"] = result.num_photometric_rows;
  state->counters["line_rows"] = result.num_line_rows;
  state->counters["iterations"] = result.summary.iterations;
  state->counters["build_ms"] = 1e3 * result.build_seconds;
  state->counters["solve_ms"] = 1e3 * result.solve_seconds;
  state->counters["rot_before_deg"] = before.rotation_rms_deg;
  state->counters["rot_after_deg"] = after.rotation_rms_deg;
  state->counters["trans_before_mm"] = 1e3 * before.translation_rms_m;
  state->counters["trans_after_mm"] = 1e3 * after.translation_rms_m;
  state->counters["idepth_med_before"] = before.idepth_relative_median;
  state->counters["idepth_med_after"] = after.idepth_relative_median;
  state->counters["idepth_rms_after"] = after.idepth_relative_rms;
}

void BM_WindowedBAWindow(benchmark::State& state) {
  const WindowedBASimulation& simulation = Window();
  WindowedBAOptions options;
  options.window = 5;
  options.max_points = static_cast<int>(state.range(0));
  const int solver = static_cast<int>(state.range(1));
  options.solver = solver == 2 ? WindowedBASolver::kGaussNewton : WindowedBASolver::kCeres;
  options.linear_solver =
      solver == 1 ? WindowedBALinearSolver::kDenseSchur : WindowedBALinearSolver::kSparseSchur;
  WindowedBAResult result;
  for (auto _ : state) {
    result = RunWindowedBA(simulation.window, options);
    benchmark::DoNotOptimize(result);
  }
  SetCounters(simulation, result, &state);
  const char* names[] = {"ceres sparse_schur", "ceres dense_schur", "gauss_newton"};
  state.SetLabel(std::string(names[solver]) + (result.summary.converged ? "" : " (not converged)"));
}
BENCHMARK(BM_WindowedBAWindow)
    ->ArgsProduct({{500, 2000}, {0, 1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);

// state.range(0): simulation seed; state.range(1): idepth_prior_scale; state.range(2):
// depth_variance_in_weights.
void BM_WindowedBAPrior(benchmark::State& state) {
  WindowedBASimulationOptions simulation_options;
  simulation_options.num_keyframes = 4;
  simulation_options.seed = static_cast<std::uint64_t>(state.range(0));
  const WindowedBASimulation simulation = SimulateWindowedBAWindow(simulation_options);
  WindowedBAOptions options;
  options.window = 4;
  options.max_points = 800;
  options.max_iterations = 50;
  options.idepth_prior_scale = static_cast<double>(state.range(1));
  options.depth_variance_in_weights = state.range(2) != 0;
  WindowedBAResult result;
  for (auto _ : state) {
    result = RunWindowedBA(simulation.window, options);
    benchmark::DoNotOptimize(result);
  }
  SetCounters(simulation, result, &state);
  state.SetLabel(result.summary.converged ? "" : "not converged");
}
BENCHMARK(BM_WindowedBAPrior)
    ->ArgsProduct({{1, 2, 3, 4, 5}, {0, 1, 10}, {1, 0}})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

}  // namespace
}  // namespace pldvo

BENCHMARK_MAIN();
