#!/usr/bin/env bash
# Installs dependencies, builds Release and runs mlidar's main job on the
# built-in default. Output goes to ./mlidar_demo (or the folder given).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
out=${1:-"$PWD/mlidar_demo"}

"$root/scripts/install_deps.sh"
cmake -S "$root" -B "$root/build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$root/build" --parallel "$(nproc)" --target mlidar
mlidar="$root/build/apps/mlidar/mlidar"

mkdir -p "$out"
data="$root/../shared/data/real"
for cloud in "$data/opencalib_3lidar/0001/top.pcd" "$data/opencalib_p64_qt/qt.pcd" "$data/scan_pair/source.ply"; do
  [[ -f "$cloud" ]] || continue
  echo "== mlidar info $cloud"
  "$mlidar" info "$cloud"
done
