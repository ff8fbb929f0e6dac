#!/usr/bin/env bash
# Lays out a `pldvo synth` sequence as a TUM monoVO folder (docs/datasets.md, `tum_mono`), with
# each frame's gain as its exposure time: images/ (links to the rendered PNGs), times.txt
# (`id timestamp exposure_ms`, exposure = 10 ms x the frame's gain from lighting.txt), a pinhole
# camera.txt and a linear pcalib.txt (G^-1 = identity). A sequence rendered with a gain swing and
# no bias (`--set gain_amplitude=0.25 --set bias_amplitude=0`) is then what an auto-exposure
# camera with a linear response records. Ground truth stays in SRC/groundtruth.txt (pass it with
# --set dataset.ground_truth=SRC/groundtruth.txt). Measured in docs/datasets.md.
# Usage: experiments/tum_mono_from_synth.sh SRC DST
set -euo pipefail
if [ $# -ne 2 ]; then
  echo "usage: $0 SRC DST   (SRC: a pldvo synth folder; DST: created)" >&2
  exit 2
fi
src=$(realpath "$1")
dst=$2
for file in rgb.txt lighting.txt camera.yaml; do
  if [ ! -f "$src/$file" ]; then
    echo "$0: $src/$file not found (not a pldvo synth folder?)" >&2
    exit 1
  fi
done
mkdir -p "$dst/images"
index=0
grep -v '^#' "$src/rgb.txt" | while read -r _ file; do
  ln -sf "$src/$file" "$dst/images/$(printf %05d.png "$index")"
  index=$((index + 1))
done
grep -v '^#' "$src/lighting.txt" | awk '{ printf "%d %s %.6f\n", NR - 1, $1, 10.0 * $2 }' \
  >"$dst/times.txt"
value() { awk -v key="$1:" '$1 == key { print $2 }' "$src/camera.yaml"; }
printf "Pinhole %s %s %s %s 0\n%s %s\n" "$(value fx)" "$(value fy)" "$(value cx)" "$(value cy)" \
  "$(value width)" "$(value height)" >"$dst/camera.txt"
seq 0 255 | tr '\n' ' ' >"$dst/pcalib.txt"
echo >>"$dst/pcalib.txt"
