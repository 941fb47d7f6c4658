# Shared by scripts/demo and scripts/test: install what is missing (Debian/Ubuntu), then
# configure and build Release in build/. Quick when everything is already there.
set -euo pipefail

HEMOTREE_ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BUILD_DIR=${HEMOTREE_BUILD_DIR:-$HEMOTREE_ROOT/build}

packages=(build-essential cmake ninja-build libboost-graph-dev libeigen3-dev
          nlohmann-json3-dev libgtest-dev libcli11-dev python3-matplotlib)

install_missing_packages() {
  local missing=()
  for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  ((${#missing[@]} == 0)) && return 0
  echo "hemotree: installing ${missing[*]}" >&2
  local sudo=()
  [ "$(id -u)" -ne 0 ] && sudo=(sudo)
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -qq
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
    "${missing[@]}" >/dev/null
}

build_release() {
  if [ ! -f "$BUILD_DIR/build.ninja" ]; then
    cmake -S "$HEMOTREE_ROOT" -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
  fi
  cmake --build "$BUILD_DIR" -- -j"$(nproc)"
}

install_missing_packages
build_release
