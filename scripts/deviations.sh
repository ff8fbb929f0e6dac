#!/usr/bin/env bash
# The deviation table (docs/deviations.md): paper.yaml (the method as published), points_lines.yaml
# (the default), paper.yaml with each extra of this implementation switched on alone and
# points_lines.yaml with each switched off alone, all through one `pldvo ablate` grid, then the
# page with each extra, why it exists and its measured effect on RPE, lost events and time.
#
# PLDVO_DEV_SET=small (default, for a shared 2-core machine): the lowtex and textured presets
# (PLDVO_DEV_PRESETS), 150 frames at 320x240 (focal length scaled: the field of view of 640x480).
# PLDVO_DEV_SET=full: the development set of scripts/benchmark.sh (scripts/dev_set.sh: every
# synthetic family at PLDVO_DEV_SEEDS, default "1 2 3", 640x480, and fr1/rpy and KITTI 00 when
# present), PLDVO_DEV_FRAMES frames (default 300), PLDVO_DEV_FILTER an extended regex on the
# sequence names. Both: PLDVO_DEV_REPEATS initial maps (default 3; mapping.init_seed 1..R),
# inline mapping (deterministic), PLDVO_DEV_JOBS runs at a time. The full set is 48 configs x 35
# sequences x R maps: a cluster job (docs/cluster.md; the grid's configs are in $dir/configs after
# the first step).
# Needs python3 with PyYAML (Debian: python3-yaml, which scripts/install_deps.sh installs) to
# write the config variants.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${PLDVO_BUILD_DIR:-build}
pldvo=${PLDVO:-$build/experiments/pldvo}
dir=${PLDVO_DEV_DIR:-/tmp/pldvo_deviations}
set_name=${PLDVO_DEV_SET:-small}
repeats=${PLDVO_DEV_REPEATS:-3}
jobs=${PLDVO_DEV_JOBS:-$(nproc)}
[ -x "$pldvo" ] || { echo "deviations.sh: build $pldvo first (scripts/build.sh)" >&2; exit 1; }
mkdir -p "$dir/configs"
datasets=()
case "$set_name" in
  small)
    frames=${PLDVO_DEV_FRAMES:-150}
    width=${PLDVO_DEV_WIDTH:-320}
    height=${PLDVO_DEV_HEIGHT:-240}
    presets=${PLDVO_DEV_PRESETS:-lowtex textured}
    # The synthetic camera's 525 px focal length is for 640x480; scaled with the width, so that
    # every size sees the same 63 deg field of view (as the tests' 320x240 sequence, f = 262.5).
    focal=$(python3 -c "print(525.0 * $width / 640)")
    for preset in $presets; do
      seq="$dir/${preset}_${frames}_${width}x${height}"
      if [ ! -f "$seq/rgb.txt" ]; then
        "$pldvo" synth --preset "$preset" --frames "$frames" --width "$width" --height "$height" \
          --set "fx=$focal" --set "fy=$focal" --out "$seq"
      fi
      datasets+=("$seq")
    done
    description="a SMALL set for a shared 2-core machine (indications, not results: rerun with \
PLDVO_DEV_SET=full): the synthetic $(echo "$presets" | sed 's/ / and /g') presets, $frames frames \
at ${width}x$height (f scaled: 63 deg field of view)"
    ;;
  full)
    frames=${PLDVO_DEV_FRAMES:-300}
    # shellcheck source=scripts/dev_set.sh
    source scripts/dev_set.sh
    mapfile -t datasets < <(dev_set_datasets "$pldvo" "$dir/seq_f$frames" "$frames" \
      "${PLDVO_DEV_SEEDS:-1 2 3}" "${PLDVO_DEV_FILTER:-.}" "$jobs")
    wait $! || { echo "deviations.sh: rendering the development set failed" >&2; exit 1; }
    description="the development set (scripts/dev_set.sh: ${#datasets[@]} sequences), at most \
$frames frames each"
    ;;
  *)
    echo "deviations.sh: PLDVO_DEV_SET must be small or full, not '$set_name'" >&2
    exit 2
    ;;
esac

# The extras: name | keys=values as in points_lines (on) | as in paper.yaml (off) | why.
cat > "$dir/deviations.tsv" <<'TSV'
edlines	lines.detector.method=edlines	lines.detector.method=lsd	EDLines finds more of the low-contrast edges of the synthetic rooms than LSD (recall 0.92 vs 0.77 at 10 gray levels) in a fifth of the time (docs/line_frontend.md).
endpoint_sigma_0.5	lines.detector.endpoint_sigma_px=0.5	lines.detector.endpoint_sigma_px=1	The endpoint sigma that Sigma_l (eq. 6) is built from, set to the detectors' measured endpoint error instead of the paper's 1 px.
max_150_segments	lines.merger.max_segments=150	lines.merger.max_segments=0	Bounds LBD and matching time on cluttered frames by keeping the longest (best localised) segments.
stereo_correlation	mapping.stereo_error_correlation=0.1	mapping.stereo_error_correlation=0	Stereo observations of a pixel share part of their error (same patch, similar baselines); the independent EKF becomes overconfident (docs/mapping.md, "Correlated observation errors").
residual_noise	mapping.residual_intensity_noise=true	mapping.residual_intensity_noise=false	Raises sigma_I^2 of an SSD match to its residual SSD / 8 so the observation variance stays consistent on poorly matching patches.
ambiguity_variance	mapping.ssd_ambiguity_variance=true	mapping.ssd_ambiguity_variance=false	Adds the likelihood-weighted spread of the search's other SSD minima to the variance of an ambiguous match.
line_ssd_check	mapping.line_stereo_check_ssd=true	mapping.line_stereo_check_ssd=false	Rejects line-guided matches whose 5-sample SSD is too large (a wrong line match).
line_noise_in_stereo	mapping.line_stereo_estimated_line_noise=true	mapping.line_stereo_estimated_line_noise=false	Scales the current line's position error in eq. 10 by the line noise the tracked frame's point-to-line errors imply (lines noisier than the detector's model, as at low contrast, give less certain depths; docs/mapping.md).
line_ssd_refine	mapping.line_stereo_ssd=refine_more_precise	mapping.line_stereo_ssd=fallback	Searches the SSD within +- 2 sigma of a line-guided match and takes its match where its variance is the smaller (the line converges, the SSD localises; docs/mapping.md).
keyframe_line_var	mapping.line_stereo_keyframe_line_var=true	mapping.line_stereo_keyframe_line_var=false	Adds the keyframe line's position error to eq. 10, shared by all of a pixel's line-guided observations.
ray_1d_regularisation	mapping.line_regularization_method=ray_1d	mapping.line_regularization_method=paper_2d	Fits the line along the pixels' rays in inverse depth with exact inverse-variance weights (no iteration) and a conservative variance (backend/mapping/line_regularizer.h).
prior_line_gate	odometry.line_prior_gate_px=2	odometry.line_prior_gate_px=0	Unmatches lines whose edge points reproject far from them at the pose prior, before tracking (wrong matches of repetitive patterns).
post_line_gate	odometry.line_outlier_px=2	odometry.line_outlier_px=0	The same check after tracking; lines that fail are unmatched and the frame is tracked again.
predicted_matching	odometry.predict_line_matches=true	odometry.predict_line_matches=false	Matches lines near their homography-predicted position (tighter radius and angle gates).
two_view_bootstrap	odometry.two_view_bootstrap=true	odometry.two_view_bootstrap=false	Starts from frame 0's map of a two-view geometry of tracked corners instead of the random map; where it fails the run starts as without it (docs/bootstrap.md).
best_of_3_starts	odometry.random_start_candidates=3	odometry.random_start_candidates=1	Where the run starts from the random map, runs the first 60 frames from three initial maps and keeps the one whose frames correlate best with their keyframes: which start a texture-less room settles into depends on the random values (docs/bootstrap.md).
photometric_random_map	odometry.random_map_warmup_updates=3	odometry.random_map_warmup_updates=0	Tracks the frames before a random start map's third stereo update photometric only: its depths are still mostly draws, and on boxes seed 2 the line rows turned them into a rotation error that the map then kept (docs/bootstrap.md).
consensus_check	odometry.line_consensus_max_cost_drop=8.4	odometry.line_consensus_max_cost_drop=0	Drops a frame's line term when a photometric-only solve from its result lowers the photometric cost by more than chi^2_6(0.99)/2: wrong line matches (repetitive patterns, occlusion edges) cannot drag the pose (docs/tracking.md).
estimated_noise	tracking.problem.weighting.intensity_noise=estimated	tracking.problem.weighting.intensity_noise=fixed	sigma_I of eq. 5 estimated from the previous frame's photometric errors instead of a fixed 4 gray levels: the ratio of photometric to point-to-line weights does not move with the camera's contrast (docs/tracking.md).
alternative_poses	odometry.try_alternatives=true	odometry.try_alternatives=false	Retries lost or high-residual frames from zero motion and small rotations; an alternative ending further from the first result than the frame's motion needs a correlation no lower (docs/odometry.md).
point_budget_4000	mapping.max_reference_points=4000	mapping.max_reference_points=0	At most 4000 tracking reference points per pyramid level: bounds the tracking time.
rms_keyframes	keyframes.max_rms_growth=1.5	keyframes.max_rms_growth=0	A new keyframe when the frame's photometric misfit exceeds 1.5x the smallest since the keyframe (DSO's criterion): a keyframe that explains the image worse and worse (exposure drift, a wrong motion) is replaced early (docs/odometry.md).
rows_per_edge_50	tracking.problem.max_rows_per_edge=50	tracking.problem.max_rows_per_edge=0	The photometric rows of one keyframe edge count as at most 50 points: an edge whose points share one wrong depth (an occluding edge that splits) cannot outvote the rest of the view through the row-wise robust loss (docs/tracking.md).
new_hypothesis_prior	mapping.new_hypothesis_prior_relative_sigma=1	mapping.new_hypothesis_prior_relative_sigma=0	Fuses a new hypothesis' first observation with a prior at the map's mean inverse depth (sigma: that mean): alone, millimetre-baseline searches land anywhere on the range and sit on its near side (docs/mapping.md, "New hypotheses").
no_line_regularisation	mapping.line_regularization=false	mapping.line_regularization=true	Leaves out the paper's 3D line regularisation (eqs. 11-13), which made points_lines worse on most of the development set (docs/mapping.md).
TSV

python3 - "$dir" <<'PY'
import os, shutil, sys, yaml
out = sys.argv[1]
def load(path):
    text = open(path).read().replace('%YAML:1.0', '', 1)
    return yaml.safe_load(text) or {}
def write(tree, name):
    with open(os.path.join(out, 'configs', name + '.yaml'), 'w') as f:
        f.write('%YAML:1.0\n---\n' + yaml.safe_dump(tree, sort_keys=False))
def setkey(tree, key, value):
    parts = key.split('.')
    for part in parts[:-1]:
        tree = tree.setdefault(part, {})
    tree[parts[-1]] = yaml.safe_load(value)
base = {n: load('experiments/configs/%s.yaml' % n) for n in ('paper', 'points_lines')}
write(base['paper'], 'paper')
write(base['points_lines'], 'points_lines')
for line in open(os.path.join(out, 'deviations.tsv')):
    name, on, off, _ = line.rstrip('\n').split('\t')
    for prefix, config, assignments in (('paper+', 'paper', on), ('points_lines-', 'points_lines', off)):
        tree = yaml.safe_load(yaml.safe_dump(base[config]))
        for assignment in assignments.split(';'):
            key, value = assignment.split('=', 1)
            setkey(tree, key, value)
        write(tree, prefix + name)
PY

configs="$dir/configs/paper.yaml,$dir/configs/points_lines.yaml"
while IFS=$'\t' read -r name _; do
  configs+=",$dir/configs/paper+$name.yaml,$dir/configs/points_lines-$name.yaml"
done < "$dir/deviations.tsv"
num_configs=$((2 + 2 * $(wc -l <"$dir/deviations.tsv")))
echo "deviations.sh: ${#datasets[@]} sequences x $num_configs configs x $repeats initial maps"
"$pldvo" ablate --configs "$configs" --datasets "$(IFS=,; echo "${datasets[*]}")" \
  --out "$dir/grid" --repeats "$repeats" --jobs "$jobs" --skip_existing --run_max_frames "$frames" \
  --set odometry.parallel_mapping=false > "$dir/ablate.log" || true

# The command that regenerates this page, with the set's settings.
command="PLDVO_DEV_SET=$set_name PLDVO_DEV_REPEATS=$repeats PLDVO_DEV_FRAMES=$frames"
[ "$set_name" = full ] && command+=" PLDVO_DEV_SEEDS=\"${PLDVO_DEV_SEEDS:-1 2 3}\""
command+=" scripts/deviations.sh"
python3 - "$dir" "$repeats" "$description" "$command" <<'PY'
import csv, os, re, statistics, sys
out, repeats, description, command = sys.argv[1:5]
rows = list(csv.DictReader(open(os.path.join(out, 'grid', 'results.csv'))))
datasets = list(dict.fromkeys(r['dataset'] for r in rows))
family = lambda d: re.sub(r'_s\d+$', '', d)
families = list(dict.fromkeys(family(d) for d in datasets))
def runs(config, dataset):
    return [r for r in rows if r['config'] == config and r['dataset'] == dataset]
def ok(config, dataset):
    return [r for r in runs(config, dataset) if r['status'] == 'ok']
def median(values):
    return statistics.median(values) if values else float('nan')
# A bad run: RPE above twice the median of paper.yaml's and points_lines.yaml's runs on its
# sequence (a map that converged to a wrong structure, a scale collapse): scale-free, so KITTI's
# 30 cm/s and a synthetic room's 3 cm/s are judged alike.
reference = {d: median([float(r['rpe_cm_s']) for c in ('paper', 'points_lines') for r in ok(c, d)])
             for d in datasets}
def summary(config, names):
    chosen = [r for d in names for r in runs(config, d)]
    good = [r for r in chosen if r['status'] == 'ok']
    return {'rpe': median([float(r['rpe_cm_s']) for r in good]), 'failed': len(chosen) - len(good),
            'bad': sum(float(r['rpe_cm_s']) > 2 * reference[r['dataset']] for r in good),
            'lost': sum(int(r['lost_events'] or 0) for r in good),
            'ms': median([float(r['ms_median_tracking_thread']) for r in good])}
def cell(s):
    x = ' (%d X)' % s['failed'] if s['failed'] else ''
    return '%.2f / %d / %d / %.0f%s' % (s['rpe'], s['bad'], s['lost'], s['ms'], x)
def change(config, ref):
    # Per sequence the ratio of the medians over the initial maps, then the median over sequences.
    ratios, ms = [], []
    for d in datasets:
        a, b = ok(config, d), ok(ref, d)
        if a and b:
            ratios.append(median([float(r['rpe_cm_s']) for r in a]) /
                          median([float(r['rpe_cm_s']) for r in b]))
            ms.append(median([float(r['ms_median_tracking_thread']) for r in a]) /
                      median([float(r['ms_median_tracking_thread']) for r in b]))
    s, t = summary(config, datasets), summary(ref, datasets)
    return '%.2f [%d / %d] / %+d / %+d / %.2f' % (
        median(ratios), sum(x < 0.9 for x in ratios), sum(x > 1.1 for x in ratios),
        s['bad'] - t['bad'], s['lost'] - t['lost'], median(ms))
lines = []
w = lines.append
w('# Deviations from the paper')
w('')
w('`experiments/configs/paper.yaml` is the method as published (Yang & Scherer, ICRA 2017); the')
w('default `points_lines.yaml` adds the extras below. Each row: what the extra changes, why it')
w('exists, and its measured effect switched on alone in paper.yaml and switched off alone in')
w('points_lines.yaml. Equation numbers are the paper\'s (eq. 1 E(xi), eq. 2 r_i, eq. 3 g_j,')
w('eq. 5 Sigma_f, eq. 6 Sigma_g, eqs. 8-10 line-guided stereo, eqs. 11-13 line regularisation).')
w('')
maps = ('one initial map per sequence (mapping.init_seed 1)' if repeats == '1' else
        '%s initial maps per sequence (mapping.init_seed 1..%s)' % (repeats, repeats))
w('Measured on %s, %s, inline mapping' % (description, maps))
w('(deterministic). A bad run has an RPE above twice the median of paper.yaml\'s and')
w('points_lines.yaml\'s runs on its sequence (a map converged to a wrong structure, a collapsed')
w('scale). First table, per sequence family: median RPE (cm/s, Sim(3)-aligned, 1 s intervals) /')
w('bad runs / lost events / median tracking-thread ms per frame (mapping inline, included);')
w('X: failed runs.')
if repeats == '1':
    w('')
    w('With one initial map a sequence\'s RPE carries the spread over maps (up to 3x on one')
    w('sequence, docs/benchmark.md): read a row by its counts of sequences better and worse and by')
    w('the median over sequences, not by one sequence\'s ratio.')
w('')
w('Regenerate: `%s` (writes this page; the grid\'s results.csv/.md/.json in' % command)
w('`${PLDVO_DEV_DIR:-/tmp/pldvo_deviations}/grid`; %d runs per sequence and initial map: the' %
  len(set(r['config'] for r in rows)))
w('full set at several maps is a cluster job, docs/cluster.md).')
w('')
w('| family | paper.yaml | points_lines.yaml |')
w('| --- | --- | --- |')
for f in families:
    names = [d for d in datasets if family(d) == f]
    w('| %s | %s | %s |' % (f, cell(summary('paper', names)), cell(summary('points_lines', names))))
w('| all | %s | %s |' % (cell(summary('paper', datasets)), cell(summary('points_lines', datasets))))
w('')
w('Second table, each change against its reference (paper.yaml for "paper + extra",')
w('points_lines.yaml for "points_lines - extra"): the median over sequences of the RPE ratio (each')
w('sequence\'s median over the initial maps) [sequences more than 10% better / worse] / change in')
w('bad runs / change in lost events / median ratio of the tracking-thread time.')
w('')
w('| extra | switch (on; paper.yaml value) | why | paper + extra | points_lines - extra |')
w('| --- | --- | --- | --- | --- |')
for line in open(os.path.join(out, 'deviations.tsv')):
    name, on, off, why = line.rstrip('\n').split('\t')
    w('| %s | `%s` (`%s`) | %s | %s | %s |' % (
        name, on.replace(';', '`, `'), off.split('=', 1)[1], why,
        change('paper+' + name, 'paper'), change('points_lines-' + name, 'points_lines')))
w('')
w('Times come from a shared machine: a row with RPE ratio 1.00 [0 / 0] most likely ran the same')
w('trajectories as its reference (the switch never acted on these sequences), so its time ratio')
w('shows how much the time varies with the load alone.')
w('')
w('Not switched: differences of this implementation that the paper does not specify either way')
w('(e.g. the half-pixel SSD search step, edge merging, the Huber loss threshold) keep their')
w('defaults in both configs (`pldvo run --list_config`, docs/config_keys.md).')
open('docs/deviations.md', 'w').write('\n'.join(lines) + '\n')
print('wrote docs/deviations.md')
PY
