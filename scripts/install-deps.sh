#!/usr/bin/env bash
# Installs stvl-bench's build and test dependencies from Debian 12's packages. Idempotent: packages already
# installed are skipped without touching apt.
#   install-deps.sh             everything: build, every test (Chromium, RViz, Slurm, fuzzing), the peers
#   install-deps.sh --runtime   only what run, replay, lint, compare, render and sweep --jobs need to build and run
#                               (then ./scripts/build.sh -DSTVL_BUILD_TESTS=OFF); about a third of the download
#   install-deps.sh --with-pcl  everything plus libpcl-dev (1.3 GB) for the peer benchmark
set -euo pipefail

# What `stvl-bench` itself needs to build (each a find_package of CMakeLists) and the report's JavaScript.
runtime=(
  build-essential cmake pkg-config
  libmujoco-dev libqhull-dev libosmesa6-dev libegl-dev libgl-dev libeigen3-dev
  libopenvdb-dev libboost-iostreams-dev
  librosbag-storage-dev libroscpp-core-dev libsensor-msgs-dev libtf2-msgs-dev libnav-msgs-dev
  libgeometry-msgs-dev libstd-msgs-dev
  libzstd-dev liblz4-dev libsqlite3-dev libssl-dev
  libyaml-cpp-dev nlohmann-json3-dev libcli11-dev libpng-dev libtbb-dev libtinyxml2-dev
  libjs-chart.js libjs-three
)
# The tests, the format check, the sanitizer and fuzz builds, the browser and RViz checks, the sweep engines, the benchmark peers.
tests=(
  libopenvdb-tools python3-rosbag clang-format
  libgtest-dev libgmock-dev libbenchmark-dev liboctomap-dev
  clang libclang-rt-14-dev
  parallel chromium
  rviz ros-core xvfb x11-apps netpbm python3-yaml
  slurm-wlm munge
)
case "${1:-}" in
  --runtime) packages=("${runtime[@]}") ;;
  --with-pcl) packages=("${runtime[@]}" "${tests[@]}" libpcl-dev) ;;
  "") packages=("${runtime[@]}" "${tests[@]}") ;;
  *) echo "install-deps: unknown option '$1' (--runtime, --with-pcl)" >&2; exit 2 ;;
esac

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
