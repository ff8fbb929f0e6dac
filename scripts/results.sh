#!/usr/bin/env bash
# Writes docs/results.md (or FILE) from the outputs that scripts/targets.sh left in OUT: the
# headline grid (OUT/headline_lowtex, OUT/headline_textured), KITTI (OUT/kitti), real data
# (OUT/real, PLDVO_REAL), the real-time timing runs (OUT/timing) and the solver comparison
# (OUT/solvers). Steps whose folder is missing get no section. Nothing is measured here; run
#   scripts/targets.sh OUT --write-results docs/results.md
# to measure and write in one go, or scripts/results.sh OUT [FILE] to rewrite the page from an
# earlier OUT. Only bash, awk and sed: results.csv of `pldvo ablate` and each run's summary.json.
set -euo pipefail
out=$(realpath "${1:?usage: scripts/results.sh OUT [FILE]}")
file=${2:-$(dirname "$0")/../docs/results.md}
code=$(git -C "$(dirname "$0")" rev-parse --short HEAD 2>/dev/null || echo unknown)
machine=$(cat "$out/machine.txt" 2>/dev/null || echo unknown)

# "dataset config median runs lost" per cell: median of column $2 over the "ok" runs of
# results.csv, lost events summed (as scripts/targets.sh).
medians() {
  awk -F, -v column="$2" 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i == column) c = i; next }
    $3 == "ok" { print $1, $2, $c, $7 }' "$1/results.csv" | sort -k1,1 -k2,2 -k3,3g |
    awk '{ key = $1 " " $2; n[key]++; v[key, n[key]] = $3; lost[key] += $4 }
      END { for (key in n) {
              m = n[key]
              if (m % 2) med = v[key, (m + 1) / 2]
              else med = (v[key, m / 2] + v[key, m / 2 + 1]) / 2
              print key, med, m, lost[key] } }' | sort
}

# One table row of median ms per component from a run's summary.json ("-" where a key is absent).
components="load pyramid detection description matching tracking mapping tracking_thread total"
component_row() {
  awk -v name="$2" -v keys="$components" '
    /"ms_median": \{/ { inside = 1; next }
    inside && /\}/ { inside = 0 }
    inside { gsub(/[",]/, ""); sub(/:/, ""); ms[$1] = $2 }
    END { n = split(keys, k, " "); row = "| " name
          for (i = 1; i <= n; ++i) row = row " | " (k[i] in ms ? sprintf("%.1f", ms[k[i]]) : "-")
          print row " |" }' "$1"
}

{
  echo "# Results"
  echo
  echo "Written by \`scripts/targets.sh OUT --write-results docs/results.md\` on $(date +%F)"
  echo "(code of \`$code\`; this machine's \`tracking_benchmark\` Gauss-Newton solve: $machine ms)."
  echo "Do not edit by hand: rerun the command. What the runs are and how RPE and ATE are defined:"
  echo "docs/targets.md, docs/odometry.md, docs/evaluation.md (RPE: cm/s and deg/s over 1 s,"
  echo "Sim(3)-aligned; ATE in metres after the Sim(3) alignment)."

  if [ -f "$out/headline_lowtex/results.csv" ]; then
    echo
    echo "## Accuracy on the synthetic sequences (headline grid)"
    echo "\`pldvo synth --preset lowtex|textured --seed 1|2|3 --frames 300\`, 640x480; mapping inline"
    echo "(\`odometry.parallel_mapping=false\`, deterministic). RPE cm/s, median over the initial maps"
    echo "(\`mapping.init_seed\` 1..R); lost events summed over the runs."
    echo
    echo "| sequence | initial maps | sdvo | points_lines | points_lines / sdvo | lost events sdvo / points_lines |"
    echo "| --- | ---: | ---: | ---: | ---: | ---: |"
    for preset in lowtex textured; do
      [ -f "$out/headline_$preset/results.csv" ] || continue
      medians "$out/headline_$preset" rpe_cm_s | awk '
        { rpe[$1, $2] = $3; runs[$1] = $4; lost[$1, $2] = $5; seen[$1] = 1 }
        END { for (d in seen)
                printf "| %s | %d | %.2f | %.2f | %.2f | %d / %d |\n", d, runs[d], rpe[d, "sdvo"],
                  rpe[d, "points_lines"], rpe[d, "points_lines"] / rpe[d, "sdvo"],
                  lost[d, "sdvo"], lost[d, "points_lines"] }' | sort
    done
  fi

  for step in kitti real; do
    [ -f "$out/$step/results.csv" ] || continue
    echo
    if [ "$step" = kitti ]; then
      echo "## KITTI 00, first 200 frames"
      echo "1241x376, 10 Hz; one run per config with the mapping thread (not deterministic)."
    else
      echo "## Real data"
      echo "The folders of \`PLDVO_REAL\`; one run per config with the mapping thread (not"
      echo "deterministic)."
    fi
    echo
    echo "| sequence | config | frames | tracked | lost events | RPE cm/s | RPE deg/s | ATE m |"
    echo "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |"
    awk -F, 'NR > 1 { if ($3 != "ok") { printf "| %s | %s | failed | | | | | |\n", $1, $2; next }
      printf "| %s | %s | %s | %s | %s | %.2f | %.2f | %.3f |\n", $1, $2, $4, $5, $7, $8, $9, $10 }' \
      "$out/$step/results.csv"
  done

  echo
  echo "## Time per component"
  echo "Median ms per frame (\`summary.json\` \`ms_median\`; docs/odometry.md, \"Outputs\"), mapping"
  echo "thread: synthetic runs 640x480 with \`odometry.wait_for_mapping=false\`, one at a time;"
  echo "\`mapping\` is per mapping job. \`-\`: not recorded."
  echo
  echo "| run | ${components// / | } |"
  echo "|$(for c in run $components; do printf ' --- |'; done)"
  for step in timing kitti real; do
    [ -f "$out/$step/results.csv" ] || continue
    awk -F, 'NR > 1 && $3 == "ok" { print $1, $2, $16 }' "$out/$step/results.csv" |
      while read -r dataset config dir; do
        component_row "$dir/summary.json" "$dataset $config"
      done
  done

  if [ -f "$out/solvers/results.csv" ]; then
    echo
    echo "## Ceres and Gauss-Newton on the same problems"
    echo "points_lines with \`odometry.compare_solver=ceres\`: every frame's tracking problem solved"
    echo "by both; RPE cm/s of each trajectory and median ms of one frame's solve."
    echo
    echo "| sequence | RPE Gauss-Newton | RPE Ceres | difference | ms per solve Gauss-Newton / Ceres |"
    echo "| --- | ---: | ---: | ---: | ---: |"
    awk -F, 'NR > 1 && $3 == "ok" { print $1, $8, $16 }' "$out/solvers/results.csv" |
      while read -r dataset rpe dir; do
        line=$(grep 'compare ceres on the same problems' "$dir/log.txt" | tail -1 || true)
        ceres=$(echo "$line" | sed -n 's/.*; RPE \([0-9.]*\) cm\/s.*/\1/p')
        ms=$(echo "$line" |
          sed -n 's/.*tracking median \([0-9.]*\) ms (run \([0-9.]*\) ms).*/\2 \/ \1/p')
        awk -v d="$dataset" -v gn="$rpe" -v ceres="${ceres:-nan}" -v ms="${ms:--}" 'BEGIN {
          diff = 100 * (ceres - gn) / gn; if (diff < 0) diff = -diff
          printf "| %s | %.3f | %.3f | %.2f%% | %s |\n", d, gn, ceres, diff, ms }'
      done | tee "$out/solvers/rows.md"
    echo
    awk -F'|' '{ split($6, ms, "/"); gn = ms[1] + 0; ceres = ms[2] + 0; if (gn <= 0) next
                 if (!n++) { g0 = g1 = gn; c0 = c1 = ceres }
                 if (gn < g0) g0 = gn; if (gn > g1) g1 = gn
                 if (ceres < c0) c0 = ceres; if (ceres > c1) c1 = ceres }
      END { if (n) printf "ms per solve over the rows: Gauss-Newton %.1f-%.1f, Ceres %.1f-%.1f.\n",
                          g0, g1, c0, c1 }' "$out/solvers/rows.md"
  fi
} > "$file"
echo "wrote $file"
