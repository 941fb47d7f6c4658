# Shared by scripts/demo and scripts/test: install what is missing (Debian/Ubuntu), then
# configure and build Release in build/. Quick when everything is already there.
#
# Each long stage says so on stderr, one plain line before and one after (no progress bars
# or carriage returns: the output is often a log or a pipe). Set before sourcing:
#   HEMOTREE_BUILD_DIR         the build folder (default build/)
#   HEMOTREE_JOBS              parallel compile jobs (default: the number of cores)
#   hemotree_cmake_args=(...)  configure options replacing -DCMAKE_BUILD_TYPE=Release; when
#                              set, the folder is configured every time (a few seconds), so
#                              that a folder made with other options gets these.
set -euo pipefail

HEMOTREE_ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BUILD_DIR=${HEMOTREE_BUILD_DIR:-$HEMOTREE_ROOT/build}
JOBS=${HEMOTREE_JOBS:-$(nproc)}

packages=(build-essential cmake ninja-build libboost-graph-dev libeigen3-dev
          nlohmann-json3-dev libgtest-dev libcli11-dev libyaml-cpp-dev zlib1g-dev python3-matplotlib
          python3-numpy python3-pandas libhdf5-openmpi-dev libopenmpi-dev openmpi-bin python3-h5py
          libmetis-dev libpetsc-real-dev pkg-config)

say() { echo "hemotree: $*" >&2; }

# heartbeat LABEL COMMAND...: runs COMMAND and, when stderr is not a terminal (where a tool's
# own progress line would be broken by it), says "LABEL: still running (N min)" each minute.
# The command stays in the foreground, so that Ctrl-C and signals reach it as usual; the
# beating loop ends with it, or within a minute of this shell.
heartbeat() {
  local label=$1 status=0
  shift
  if [ -t 2 ]; then "$@"; return; fi
  local parent=$$
  (
    minutes=0
    while sleep 60 </dev/null >/dev/null 2>&1 && kill -0 "$parent" 2>/dev/null; do
      minutes=$((minutes + 1))
      say "$label: still running ($minutes min)"
    done
  ) &
  local beat=$!
  "$@" || status=$?
  kill "$beat" 2>/dev/null || true
  wait "$beat" 2>/dev/null || true
  return "$status"
}

install_missing_packages() {
  local missing=()
  for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  ((${#missing[@]} == 0)) && return 0
  local sudo=() start=$SECONDS
  [ "$(id -u)" -ne 0 ] && sudo=(sudo)
  # apt-get -qq prints nothing for minutes: announce each step and its end instead.
  say "installing ${#missing[@]} packages with apt-get (about 3 minutes on a fresh machine): ${missing[*]}"
  say "apt-get update: reading the package lists..."
  heartbeat "apt-get update" "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -qq
  say "apt-get install: downloading and unpacking ${#missing[@]} packages and their dependencies..."
  heartbeat "apt-get install" "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive \
    apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  say "installed ${#missing[@]} packages in $((SECONDS - start)) s"
}

build_release() {
  local args=(-DCMAKE_BUILD_TYPE=Release) start=$SECONDS
  local configure=0
  [ -f "$BUILD_DIR/build.ninja" ] || configure=1
  if [ -n "${hemotree_cmake_args+set}" ]; then
    args=("${hemotree_cmake_args[@]}")
    configure=1
  fi
  # ccache, where installed, makes a rebuild after switching branches or flags quick.
  if command -v ccache >/dev/null; then args+=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
  if ((configure)); then
    say "configuring $BUILD_DIR (cmake ${args[*]})"
    cmake -S "$HEMOTREE_ROOT" -B "$BUILD_DIR" -G Ninja "${args[@]}" >/dev/null
  fi
  # Ninja prints one "[n/N] Building ..." line per file when its output is not a terminal
  # (redrawn in place on a terminal); nothing at all when everything is up to date.
  say "building in $BUILD_DIR with $JOBS jobs (the first build takes several minutes; a line per file)"
  if ! cmake --build "$BUILD_DIR" -- -j"$JOBS"; then
    say "the build in $BUILD_DIR failed after $((SECONDS - start)) s (the compiler's message is above)"
    exit 1
  fi
  say "build up to date ($((SECONDS - start)) s)"
}

install_missing_packages
build_release
