#!/usr/bin/env bash
# Installs dependencies and builds pldvo (Release) into ${PLDVO_BUILD_DIR:-build}.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh
build=${PLDVO_BUILD_DIR:-build}
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j "$(nproc)"
