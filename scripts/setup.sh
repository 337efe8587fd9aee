# Shared by scripts/bench and scripts/test (sourced, not run): installs what
# is missing from Debian, configures and builds Release. Works from any
# working directory; the build lives in <repo>/build unless RAYBENCH_BUILD_DIR
# says otherwise. With RAYBENCH_SETUP_NO_BUILD=1 it only installs (scripts
# that build elsewhere: scripts/fuzz, scripts/test-sanitized).
set -eu

RAYBENCH_ROOT=$(cd "$(dirname "$(readlink -f "$0")")/.." && pwd)
RAYBENCH_BUILD_DIR=${RAYBENCH_BUILD_DIR:-"$RAYBENCH_ROOT/build"}
export RAYBENCH_ROOT RAYBENCH_BUILD_DIR

# Every Debian package raybench builds, tests or plots with.
RAYBENCH_PACKAGES="cmake ninja-build g++ git pkg-config libembree-dev libassimp-dev assimp-utils assimp-testmodels \
libeigen3-dev libbenchmark-dev libgtest-dev libtbb-dev libcli11-dev libfmt-dev libtomlplusplus-dev libcgal-dev libgmp-dev libmpfr-dev \
python3 python3-numpy python3-matplotlib"
# What scripts/fuzz adds: clang and its libFuzzer and sanitizer runtimes
# (Debian 12's clang is 14; the runtimes must be clang's own version).
RAYBENCH_FUZZ_PACKAGES="clang-14 libclang-rt-14-dev"

# raybench_install_packages [PACKAGES]: installs those of PACKAGES (default
# RAYBENCH_PACKAGES) that are missing, or names them and stops.
raybench_install_packages() {
  missing=""
  # shellcheck disable=SC2048  # package names never hold spaces
  for p in ${*:-$RAYBENCH_PACKAGES}; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
  done
  [ -z "$missing" ] && return 0
  if [ "$(id -u)" = 0 ]; then
    echo "raybench setup: installing$missing" >&2
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq >&2
    # shellcheck disable=SC2086
    apt-get install -y -qq --no-install-recommends $missing >&2
  else
    echo "raybench setup: missing Debian packages. Install them with:" >&2
    echo "  sudo apt-get install -y$missing" >&2
    exit 1
  fi
}

# raybench_build [SOURCE BUILD [cmake options]]: configures (once) and builds
# Release; this checkout into $RAYBENCH_BUILD_DIR without arguments.
raybench_build() {
  src=${1:-$RAYBENCH_ROOT}
  dir=${2:-$RAYBENCH_BUILD_DIR}
  if [ $# -ge 2 ]; then shift 2; else set --; fi
  jobs=$(nproc 2>/dev/null || echo 2)
  if [ ! -f "$dir/build.ninja" ]; then
    cmake -S "$src" -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Release "$@" >&2
  fi
  cmake --build "$dir" -j "$jobs" >&2
}

raybench_install_packages
if [ "${RAYBENCH_SETUP_NO_BUILD:-0}" != 1 ]; then
  raybench_build
fi
