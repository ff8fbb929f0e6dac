#!/usr/bin/env bash
# One command, one table (issue #41, docs/benchmark.md): renders the development set (every
# synthetic family at a few seeds) unless present, adds the real sequences when present, runs
# sdvo and points_lines on all of them from several random initial maps through `pldvo ablate`,
# and prints per sequence: RPE cm/s, the RPE of an estimate that never moves, rotation RPE deg/s,
# lost events, scale segments and the motion direction error, each the median [min, max] over
# the initial maps, with the points_lines / sdvo ratio of the medians; then one line per target.
#
# Usage: scripts/benchmark.sh OUT
# Environment:
#   PLDVO_BENCH_REPEATS  initial maps per (sequence, config) (default 8; mapping.init_seed 1..R)
#   PLDVO_BENCH_FRAMES   frames per sequence (default 300; also caps the real sequences)
#   PLDVO_BENCH_SEEDS    synthetic seeds (default "1 2 3")
#   PLDVO_BENCH_FILTER   extended regex: only the sequences whose name matches (e.g.
#                        '^(lowtex|boxes)_s1$'); default all
#   PLDVO_BENCH_JOBS     runs in parallel (default 2)
#   PLDVO_BENCH_SET      extra `--set key=value` arguments for every run (default none; e.g.
#                        '--set odometry.mapping_lag=0', the map of every earlier frame)
#   PLDVO_TUM_RPY, PLDVO_KITTI  the real sequences (default ../shared/data/tum_fr1_rpy and
#                        ../shared/data/kitti00_first200 relative to the repository; skipped with
#                        a message when absent)
# Sequences (scripts/dev_set.sh) are rendered into OUT/seq_f<frames>/ and kept; runs already in OUT are kept (pldvo
# ablate --skip_existing), so an interrupted benchmark resumes. The runs map inline
# (odometry.parallel_mapping=false; the same results as the mapping thread, odometry.mapping_lag).
# The full set (13 families x 3 seeds + 2 real, x 2 configs x 8 maps, 300 frames) is about 660
# runs: hours on 2 cores.
set -euo pipefail
if [ $# -ne 1 ]; then
  sed -n '2,/^set -euo/p' "$0" | sed '$d' | sed 's/^# \{0,1\}//'
  exit 2
fi
repo=$(cd "$(dirname "$0")/.." && pwd)
out=$(realpath -m "$1")
repeats=${PLDVO_BENCH_REPEATS:-8}
frames=${PLDVO_BENCH_FRAMES:-300}
seeds=${PLDVO_BENCH_SEEDS:-1 2 3}
filter=${PLDVO_BENCH_FILTER:-.}
jobs=${PLDVO_BENCH_JOBS:-2}
cd "$repo"
build=${PLDVO_BUILD_DIR:-build}
pldvo="$build/experiments/pldvo"
[ -x "$pldvo" ] || scripts/build.sh >/dev/null
configs=experiments/configs

source scripts/dev_set.sh
mapfile -t datasets < <(dev_set_datasets "$pldvo" "$out/seq_f$frames" "$frames" "$seeds" "$filter" \
  "$jobs")
wait $! || { echo "benchmark: rendering the development set failed" >&2; exit 1; }
if [ ${#datasets[@]} -eq 0 ]; then
  echo "benchmark: no sequence matches PLDVO_BENCH_FILTER='$filter'" >&2
  exit 2
fi

ablation="$out/ablation_f${frames}_r$repeats"
list=$(IFS=,; echo "${datasets[*]}")
echo "benchmark: ${#datasets[@]} sequences x 2 configs x $repeats initial maps -> $ablation"
# shellcheck disable=SC2086  # PLDVO_BENCH_SET is a list of arguments
"$pldvo" ablate --configs "$configs/sdvo.yaml,$configs/points_lines.yaml" --datasets "$list" \
  --repeats "$repeats" --jobs "$jobs" --skip_existing --run_max_frames "$frames" \
  --set odometry.parallel_mapping=false ${PLDVO_BENCH_SET:-} --out "$ablation" \
  >"$ablation.log" 2>&1 ||
  echo "benchmark: a run failed (see $ablation/results.md and the runs' log.txt)"

# The table: results.csv's columns by name (new columns are appended there), only the
# sequences of this invocation.
wanted=$(for d in "${datasets[@]}"; do basename "$d"; done | tr '\n' ' ')
awk -F, -v wanted="$wanted" -v repeats="$repeats" -v frames="$frames" '
  function sort_values(key, n,    i, j, t) {
    for (i = 2; i <= n; ++i) {
      t = v[key, i]
      for (j = i - 1; j >= 1 && v[key, j] > t; --j) v[key, j + 1] = v[key, j]
      v[key, j + 1] = t
    }
  }
  function median(key, n) {
    if (n == 0) return ""
    sort_values(key, n)
    return n % 2 ? v[key, (n + 1) / 2] : (v[key, n / 2] + v[key, n / 2 + 1]) / 2
  }
  function cell(key, n, f,    m) {
    if (n == 0) return "X"
    m = median(key, n)
    med[key] = m
    return sprintf(f " [" f ", " f "]", m, v[key, 1], v[key, n])
  }
  NR == 1 { for (i = 1; i <= NF; ++i) col[$i] = i; next }
  {
    d = $col["dataset"]; c = $col["config"]
    if (index(" " wanted, " " d " ") == 0) next
    if (!(d in seen)) { order[++nd] = d; seen[d] = 1 }
    runs[d, c]++
    if ($col["status"] != "ok") next
    ok[d, c]++
    k = ok[d, c]
    v[d SUBSEP c SUBSEP "rpe", k] = $col["rpe_cm_s"]
    v[d SUBSEP c SUBSEP "deg", k] = $col["rpe_deg_s"]
    v[d SUBSEP c SUBSEP "lost", k] = $col["lost_events"]
    v[d SUBSEP c SUBSEP "seg", k] = $col["scale_segments"]
    v[d SUBSEP c SUBSEP "dir", k] = $col["motion_direction_error_deg_median"]
    if ("rpe_cm_s_still" in col) v[d SUBSEP c SUBSEP "still", k] = $col["rpe_cm_s_still"]
  }
  END {
    # "still": the RPE of an estimate that never moves (the motion of the ground truth per
    # second, docs/evaluation.md); absent from results.csv files written before it existed.
    names = "rpe deg lost seg dir"
    if ("rpe_cm_s_still" in col) names = "rpe still deg lost seg dir"
    num_metrics = split(names, metrics, " ")
    label["rpe"] = "RPE cm/s"; label["still"] = "still cm/s"; label["deg"] = "RPE deg/s"
    label["lost"] = "lost events"; label["seg"] = "scale segments"
    label["dir"] = "motion dir deg"
    fmt["rpe"] = "%.2f"; fmt["still"] = "%.2f"; fmt["deg"] = "%.3f"; fmt["lost"] = "%g"
    fmt["seg"] = "%g"
    fmt["dir"] = "%.1f"
    for (i = 1; i <= nd; ++i) {
      d = order[i]
      printf "\n%s (%s frames, median [min, max] over %d initial maps; ok runs %d / %d sdvo, " \
             "%d / %d points_lines)\n", d, frames, repeats, ok[d, "sdvo"], runs[d, "sdvo"],
             ok[d, "points_lines"], runs[d, "points_lines"]
      printf "  %-15s %-26s %-26s %s\n", "", "sdvo", "points_lines", "pl/sdvo"
      for (m = 1; m <= num_metrics; ++m) {
        key = metrics[m]
        a = cell(d SUBSEP "sdvo" SUBSEP key, ok[d, "sdvo"], fmt[key])
        b = cell(d SUBSEP "points_lines" SUBSEP key, ok[d, "points_lines"], fmt[key])
        ma = med[d SUBSEP "sdvo" SUBSEP key]; mb = med[d SUBSEP "points_lines" SUBSEP key]
        ratio = (ok[d, "sdvo"] && ok[d, "points_lines"] && ma > 0 && (key == "rpe" || key == "deg")) \
          ? sprintf("%.2f", mb / ma) : "-"
        printf "  %-15s %-26s %-26s %s\n", label[key], a, b, ratio
        if (key == "rpe") {
          rpe_ratio[d] = ratio
          na = ok[d, "sdvo"]; nb = ok[d, "points_lines"]
          ka = d SUBSEP "sdvo" SUBSEP key; kb = d SUBSEP "points_lines" SUBSEP key
          if (na && v[ka, 1] > 0 && v[ka, na] / v[ka, 1] > 1.5) spread = spread " " d "/sdvo"
          if (nb && v[kb, 1] > 0 && v[kb, nb] / v[kb, 1] > 1.5) spread = spread " " d "/points_lines"
        }
        if (key == "lost") { lost_sdvo[d] = ma; lost_pl[d] = mb }
        if (key == "seg") seg_pl[d] = mb
      }
    }
    # Targets (docs/benchmark.md), over the sequences of this invocation.
    n_ratio = 0; worse = ""; n_lost = 0; more_lost = ""; n_seg = 0; split_seg = ""
    missing = ""
    for (i = 1; i <= nd; ++i) {
      d = order[i]
      if (ok[d, "sdvo"] < runs[d, "sdvo"] || ok[d, "points_lines"] < runs[d, "points_lines"]) {
        missing = missing " " d
      }
      if (rpe_ratio[d] != "-") { ++n_ratio; if (rpe_ratio[d] + 0 > 1.1) worse = worse " " d }
      if (lost_pl[d] != "") { ++n_lost; if (lost_pl[d] > lost_sdvo[d]) more_lost = more_lost " " d }
      if (seg_pl[d] != "") { ++n_seg; if (seg_pl[d] > 1) split_seg = split_seg " " d }
    }
    print ""
    printf "target: points_lines RPE <= 1.1 x sdvo RPE (medians) on every sequence: %s\n",
           worse == "" ? "met (" n_ratio " sequences)" : "NOT MET on" worse
    printf "target: max / min RPE over the initial maps <= 1.5 for both configs: %s\n",
           spread == "" ? "met" : "NOT MET on" spread
    printf "target: points_lines median lost events <= sdvo: %s\n",
           more_lost == "" ? "met (" n_lost " sequences)" : "NOT MET on" more_lost
    printf "target: points_lines median scale segments = 1: %s\n",
           split_seg == "" ? "met (" n_seg " sequences)" : "NOT MET on" split_seg
    printf "target: every run evaluated: %s\n", missing == "" ? "met" : "NOT MET on" missing
  }' "$ablation/results.csv"
# A ground truth that starts with extrapolated poses (KITTI 00's first 14, docs/evaluation.md):
# the same runs from the last of them on, median over the initial maps.
for d in "${datasets[@]}"; do
  name=$(basename "$d")
  for config in sdvo points_lines; do
    for run in "$ablation/runs/${name}__${config}__"*/; do
      [ -f "$run/trajectory.txt" ] || continue
      json=$("$pldvo" eval --gt "$run/groundtruth.txt" --est "$run/trajectory.txt" --json \
        --set skip_constant_velocity_start=true 2>/dev/null) || continue
      echo "$json" | grep -q '"skipped_ground_truth_poses":[1-9]' || continue
      echo "$json" | grep -o '"rpe_cm_s":[0-9.e+-]*' | cut -d: -f2
    done | sort -g | awk -v c="$config" -v d="$name" '{ v[NR] = $1 } END { if (NR == 0) exit
      m = NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2
      printf "%s %-13s from the last pose of its ground truth'"'"'s constant-velocity start: " \
        "RPE %.2f [%.2f, %.2f] cm/s\n", d, c, m, v[1], v[NR] }'
  done
done
# Over the sequences: the geometric mean of the per-sequence ratios with its bootstrap interval
# and the sign test (docs/benchmark.md, "Comparing two configurations").
echo
echo "points_lines against sdvo over the sequences (RPE cm/s, pldvo compare):"
"$pldvo" compare --baseline "$ablation" --baseline_config sdvo --candidate "$ablation" \
  --candidate_config points_lines | sed -n '/^sequences compared/,$p'
echo
echo "Tables of the ablation: $ablation/results.md; runs: $ablation/runs/"
