// `pldvo synth`: renders a synthetic indoor sequence in the TUM layout (docs/synthetic.md).
//   pldvo synth --preset lowtex --frames 300 --seed 1 --out /tmp/synth_lowtex
// Every SynthOptions field is settable with --set key=value (pldvo synth --help lists them);
// the common ones also have flags. Flags and --set override the preset's defaults.
#include <gflags/gflags.h>

#include <chrono>
#include <exception>
#include <iomanip>
#include <iostream>
#include <string>

#include "core/config_io.h"
#include "experiments/cli/command.h"
#include "experiments/cli/common_flags.h"
#include "experiments/synthetic/synthetic_sequence.h"

DEFINE_string(preset, "lowtex",
              "Scene appearance and motion: textured | lowtex | lighting | fast | autoexposure | "
              "checkerboard | boxes | handheld (docs/synthetic.md).");
DEFINE_int32(frames, 300, "Number of frames (30 fps).");
DEFINE_int32(seed, 1, "Seed of the scene layout, trajectory and noise.");
DEFINE_int32(width, 640, "Image width in pixels.");
DEFINE_int32(height, 480, "Image height in pixels.");
DEFINE_double(noise_sigma, 1.0, "Gaussian sensor noise in gray levels.");
DEFINE_int32(supersampling, 4, "n x n anti-aliasing samples at surface boundaries; 1 = off.");
DEFINE_bool(motion_blur, false, "Average sub-frame renderings over the exposure.");
DEFINE_bool(vignetting, false, "Darken the image towards the corners.");
DEFINE_double(speed, -1.0, "Mean camera speed in m/s; < 0: the preset's.");
DEFINE_int32(threads, 0, "Render threads; 0 = hardware concurrency.");
DEFINE_bool(list_options, false, "Print every --set key with its default and doc, then exit.");

namespace pldvo {
namespace {

// Copies the flags the user gave into the options (defaults leave the options alone).
void ApplyFlags(synthetic::SynthOptions* options) {
  auto given = [](const char* name) {
    return !gflags::GetCommandLineFlagInfoOrDie(name).is_default;
  };
  if (given("preset")) options->preset = FLAGS_preset;
  if (given("frames")) options->frames = FLAGS_frames;
  if (given("seed")) options->seed = FLAGS_seed;
  if (given("width")) options->width = FLAGS_width;
  if (given("height")) options->height = FLAGS_height;
  if (given("noise_sigma")) options->noise_sigma = FLAGS_noise_sigma;
  if (given("supersampling")) options->supersampling = FLAGS_supersampling;
  if (given("motion_blur")) options->motion_blur = FLAGS_motion_blur;
  if (given("vignetting")) options->vignetting = FLAGS_vignetting;
  if (given("speed")) options->speed = FLAGS_speed;
  if (given("threads")) options->threads = FLAGS_threads;
}

int RunSynth(const CommandContext& context) {
  try {
    synthetic::SynthOptions options;
    if (FLAGS_list_options) {
      std::cout << DescribeConfig(options);
      return 0;
    }
    if (FLAGS_out.empty()) {
      std::cerr << "pldvo synth: --out DIR is required\n";
      return 2;
    }
    ApplyFlags(&options);
    ApplyOverrides(context.config_overrides, &options);
    const auto start = std::chrono::steady_clock::now();
    const synthetic::SyntheticSequence sequence = synthetic::MakeSequence(options);
    const double setup_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double render_fps = synthetic::WriteSequence(sequence, FLAGS_out);
    const double total_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const int frames = sequence.options.frames;
    std::cout << std::fixed << std::setprecision(1) << "pldvo synth: " << frames << " frames "
              << sequence.options.width << "x" << sequence.options.height << " preset "
              << sequence.options.preset << " seed " << sequence.options.seed << " -> " << FLAGS_out
              << "\n  scene: " << sequence.scene.primitives().size() << " primitives, "
              << sequence.scene.edges().size() << " 3D edges; trajectory " << std::setprecision(2)
              << setup_seconds << " s\n  rendering: " << std::setprecision(1) << render_fps
              << " frames/s; total with PNG output: " << frames / total_seconds << " frames/s ("
              << std::setprecision(2) << total_seconds << " s)\n";
    return 0;
  } catch (const std::exception& error) {
    std::cerr << "pldvo synth: " << error.what() << "\n";
    return 1;
  }
}

PLDVO_REGISTER_COMMAND("synth",
                       "Render a synthetic indoor sequence (TUM layout) with ground truth.",
                       RunSynth, "out");

}  // namespace
}  // namespace pldvo
