# The development set (issue #41), sourced by scripts/benchmark.sh and scripts/deviations.sh:
# every synthetic family at a few seeds, rendered once and kept, and the real sequences when
# present. Usage, after `source scripts/dev_set.sh`:
#   dev_set_datasets PLDVO FOLDER FRAMES "SEEDS" FILTER JOBS
# renders what FOLDER lacks and prints one dataset folder per line. FILTER is an extended regex on
# the sequence names (<family>_s<seed>, tum_fr1_rpy, kitti00_first200). The real sequences are
# ${PLDVO_TUM_RPY:-../shared/data/tum_fr1_rpy} and ${PLDVO_KITTI:-../shared/data/kitti00_first200}
# relative to the repository; an absent one is skipped with a message on stderr.

# family name -> pldvo synth arguments. Names avoid dots: ablate names a sequence by its folder.
dev_set_families=(
  "lowtex|--preset lowtex"
  "textured|--preset textured"
  "contrast050|--preset lowtex --set contrast=0.5"
  "contrast075|--preset lowtex --set contrast=0.75"
  "contrast125|--preset lowtex --set contrast=1.25"
  "brightp20|--preset lowtex --set brightness=0.2"
  "brightm20|--preset lowtex --set brightness=-0.2"
  "autoexposure|--preset autoexposure"
  "vignetting|--preset lowtex --vignetting"
  "checkerboard|--preset checkerboard"
  "boxes|--preset boxes"
  "handheld|--preset handheld"
  "pivot|--preset handheld --set pivot_distance=0.25"
)

dev_set_datasets() {
  local pldvo=$1 folder=$2 frames=$3 seeds=$4 filter=$5 jobs=$6
  local repo entry family seed name real
  local -a args
  repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
  mkdir -p "$folder"
  for entry in "${dev_set_families[@]}"; do
    family=${entry%%|*}
    # shellcheck disable=SC2206
    args=(${entry#*|})
    for seed in $seeds; do
      name="${family}_s$seed"
      echo "$name" | grep -Eq -- "$filter" || continue
      if [ ! -f "$folder/$name/rgb.txt" ]; then
        echo "dev_set: rendering $name ($frames frames)" >&2
        rm -rf "$folder/$name.partial"
        "$pldvo" synth "${args[@]}" --seed "$seed" --frames "$frames" --threads "$jobs" \
          --out "$folder/$name.partial" >/dev/null
        mv "$folder/$name.partial" "$folder/$name"
      fi
      echo "$folder/$name"
    done
  done
  for real in "${PLDVO_TUM_RPY:-$repo/../shared/data/tum_fr1_rpy}" \
              "${PLDVO_KITTI:-$repo/../shared/data/kitti00_first200}"; do
    real=$(realpath -m "$real")
    name=$(basename "$real")
    echo "$name" | grep -Eq -- "$filter" || continue
    if [ -f "$real/rgb.txt" ]; then
      echo "$real"
    else
      echo "dev_set: skipping $name: no $real/rgb.txt" >&2
    fi
  done
}
