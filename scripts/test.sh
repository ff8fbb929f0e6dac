#!/usr/bin/env bash
# Installs dependencies, builds pldvo (Release) and runs every test. Usage: scripts/test.sh
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh
ctest --test-dir "${PLDVO_BUILD_DIR:-build}" -j "$(nproc)" --output-on-failure
