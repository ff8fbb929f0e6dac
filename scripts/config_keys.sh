#!/usr/bin/env bash
# Writes the key table of `pldvo run --list_config` (DescribeConfig) on two pages, each with a
# short header: docs/config_keys.md (dataset, lines, tracking, mapping, keyframes) and
# docs/config_keys_backend.md (from the `odometry` section on), so that each stays near 300 lines.
# ConfigKeysDocTest (tests/experiments/shipped_configs_test.cc) fails when the committed pages
# differ from the binary's table: run this after changing an option.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${PLDVO_BUILD_DIR:-build}
pldvo="$build/experiments/pldvo"
[ -x "$pldvo" ] || { echo "config_keys.sh: build $pldvo first (scripts/build.sh)" >&2; exit 1; }
table=$("$pldvo" run --list_config)
split='| **`odometry`** | section'
head_rows=$(printf '%s\n' "$table" | head -n 2)
first=$(printf '%s\n' "$table" | awk -v s="$split" 'index($0, s) == 1 { exit } { print }')
second=$(printf '%s\n' "$table" | awk -v s="$split" 'index($0, s) == 1 { on = 1 } on { print }')
[ -n "$second" ] || { echo "config_keys.sh: no odometry section in the table" >&2; exit 1; }
{
  cat <<'HEADER'
# Config keys: frontend, tracking and mapping

Every key of `OdometryConfig` with its type, default and doc (`pldvo run --list_config`), written
by `scripts/config_keys.sh` (`ConfigKeysDocTest` fails when stale); see docs/configuration.md.
The odometry, output, back-end and evaluation keys: docs/config_keys_backend.md.

HEADER
  printf '%s\n' "$first"
} > docs/config_keys.md
{
  cat <<'HEADER'
# Config keys: odometry, output, back end and evaluation

The second half of `pldvo run --list_config` (docs/config_keys.md has the first, and how both are
written).

HEADER
  printf '%s\n' "$head_rows" "$second"
} > docs/config_keys_backend.md
echo "wrote docs/config_keys.md and docs/config_keys_backend.md"
