#!/usr/bin/env bash
# Installs pldvo's build and test dependencies from Debian 12 packages. Idempotent: when every
# package is already installed it returns at once without touching apt.
set -euo pipefail
packages=(
  build-essential cmake ninja-build pkg-config clang clang-format libclang-rt-14-dev
  libceres-dev libeigen3-dev libsuitesparse-dev libgflags-dev libgoogle-glog-dev
  libopencv-dev libopencv-contrib-dev libgtest-dev libgmock-dev libbenchmark-dev
  nlohmann-json3-dev libzip-dev python3-yaml libyaml-cpp-dev
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then exit 0; fi
echo "install_deps: installing ${missing[*]}" >&2
sudo_cmd=""
if [ "$(id -u)" -ne 0 ]; then sudo_cmd="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$sudo_cmd apt-get update -qq
$sudo_cmd apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
