#!/usr/bin/env bash
# Writes docs/config_keys.md: a short header and the key table of `pldvo run --list_config`
# (DescribeConfig). ConfigKeysDocTest (tests/experiments/shipped_configs_test.cc) fails when the
# committed file differs from the binary's table: run this after changing an option.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${PLDVO_BUILD_DIR:-build}
pldvo="$build/experiments/pldvo"
[ -x "$pldvo" ] || { echo "config_keys.sh: build $pldvo first (scripts/build.sh)" >&2; exit 1; }
{
  cat <<'HEADER'
# Config keys

Every key of `OdometryConfig` with its type, default and doc (`pldvo run --list_config`), written
by `scripts/config_keys.sh` (`ConfigKeysDocTest` fails when stale); see docs/configuration.md.

HEADER
  "$pldvo" run --list_config
} > docs/config_keys.md
echo "wrote docs/config_keys.md"
