#!/usr/bin/env bash
# The main job on an embedded default: builds pldvo, renders two synthetic sequences with ground
# truth (a low-texture room and a textured one), runs the semi-dense VO baseline (sdvo) and the
# paper's points-and-lines odometry (points_lines) on both through `pldvo ablate`, and prints the
# RPE table (the paper's Tables I/II; docs/odometry.md). A few minutes on 2 cores.
# The runs map inline (odometry.parallel_mapping=false: the same algorithm, no mapping thread), so
# the table is the same on every run and the README can quote it; with the mapping thread the map
# a frame is tracked against depends on thread timing.
# Outputs in ${PLDVO_DEMO_DIR:-/tmp/pldvo_demo}: results.md, results.csv, trajectories_*.svg and
# every run's trajectory, timing and summary under runs/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh
build=${PLDVO_BUILD_DIR:-build}
pldvo="$build/experiments/pldvo"
demo=${PLDVO_DEMO_DIR:-/tmp/pldvo_demo}
frames=${PLDVO_DEMO_FRAMES:-300}
mkdir -p "$demo"
for preset in lowtex textured; do
  if [ ! -f "$demo/$preset/rgb.txt" ]; then
    "$pldvo" synth --preset "$preset" --frames "$frames" --out "$demo/$preset"
  fi
done
"$pldvo" ablate --configs experiments/configs/sdvo.yaml,experiments/configs/points_lines.yaml \
  --datasets "$demo/lowtex,$demo/textured" --out "$demo/ablation" --jobs "$(nproc)" \
  --set odometry.parallel_mapping=false
echo "Trajectory plots: $demo/ablation/trajectories_lowtex.svg, trajectories_textured.svg"
