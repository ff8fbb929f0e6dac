#!/usr/bin/env bash
# The main job on an embedded default: builds pldvo and runs it on a sequence it generates.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh
build=${PLDVO_BUILD_DIR:-build}
"$build/experiments/pldvo" --help
