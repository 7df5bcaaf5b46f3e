#!/usr/bin/env bash
# Installs every Debian package mlidar's build, tests, benchmarks and fuzzers
# need. Idempotent and fast: apt is called only when something is missing.
set -euo pipefail

packages=(
  build-essential cmake ninja-build git pkg-config
  clang libclang-rt-14-dev lld
  libeigen3-dev libceres-dev libnanoflann-dev robin-map-dev libtbb-dev
  libyaml-cpp-dev libcli11-dev libspdlog-dev libfmt-dev nlohmann-json3-dev liblzf-dev
  libbz2-dev liblz4-dev libzstd-dev libsqlite3-dev
  python3-yaml python3-rosbag python3-sensor-msgs python3-tf2-msgs python3-roslz4 python3-zstandard python3-lz4
  libgtest-dev libgmock-dev libbenchmark-dev zlib1g-dev
  chromium fonts-liberation
  python3-dev pybind11-dev python3-numpy python3-pytest python3-dask python3-distributed
  libtorch-dev
)

missing=()
for package in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$package" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$package")
done

if ((${#missing[@]} == 0)); then
  echo "install_deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install_deps: installing ${missing[*]}"
sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then sudo_cmd=(sudo); fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
