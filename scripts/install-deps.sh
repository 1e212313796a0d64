#!/usr/bin/env bash
# Installs stvl-bench's build and test dependencies from Debian 12's packages. Idempotent: packages already
# installed are skipped without touching apt. Pass --with-pcl to add libpcl-dev (1.3 GB) for the peer benchmark.
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libmujoco-dev libqhull-dev libosmesa6-dev libegl-dev libgl-dev libeigen3-dev
  libopenvdb-dev libboost-iostreams-dev libopenvdb-tools
  librosbag-storage-dev libroscpp-core-dev libsensor-msgs-dev libtf2-msgs-dev libnav-msgs-dev
  libgeometry-msgs-dev libstd-msgs-dev python3-rosbag
  libzstd-dev liblz4-dev libsqlite3-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libyaml-cpp-dev nlohmann-json3-dev libcli11-dev libpng-dev libtbb-dev liboctomap-dev
  clang libclang-rt-14-dev
  parallel libjs-chart.js libjs-three chromium
  rviz ros-core xvfb x11-apps netpbm python3-yaml
  slurm-wlm munge
)
[[ "${1:-}" == "--with-pcl" ]] && packages+=(libpcl-dev)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#packages[@]} packages already installed"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
sudo_cmd=()
[[ $(id -u) -ne 0 ]] && sudo_cmd=(sudo)
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
