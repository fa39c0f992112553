#!/usr/bin/env bash
# Installs everything rig_calibrator needs on Debian 12 (bookworm) and builds COLMAP 3.8's
# libraries, headers and command-line tool from Debian's source package into a cache prefix
# outside the repository, keeping the unpacked source beside it ($cache/src/colmap-3.8: the
# project's extended `colmap` compiles COLMAP's command sources from it). Idempotent: a rerun
# with the cache in place skips the COLMAP build, and unpacks the source again if it is gone.
#
# Environment:
#   RIG_CALIBRATOR_CACHE  cache folder (default: $HOME/.cache/rig_calibrator)
#   RIG_CALIBRATOR_SKIP_APT=1  do not call apt-get (all packages already installed)
#
# The system's package sources are not changed: the deb-src entry needed for
# `apt-get source colmap` lives in a private sources list and list folder inside the cache.
set -euo pipefail

cache="${RIG_CALIBRATOR_CACHE:-$HOME/.cache/rig_calibrator}"
prefix="$cache/colmap-3.8"
stamp="$prefix/.rig_calibrator_build_ok"
jobs="$(nproc 2>/dev/null || echo 2)"

say() { echo "[setup] $*"; }
die() { echo "[setup] ERROR: $*" >&2; exit 1; }

sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null 2>&1 || die "not root and no sudo: run as root or install sudo."
  sudo_cmd=(sudo)
fi

packages=(
  build-essential cmake ninja-build git pkg-config dpkg-dev ca-certificates
  libeigen3-dev libceres-dev libgoogle-glog-dev libgflags-dev libflann-dev
  libfreeimage-dev libmetis-dev libsqlite3-dev libglew-dev libsuitesparse-dev liblz4-dev
  libboost-program-options-dev libboost-filesystem-dev libboost-graph-dev
  libboost-regex-dev libboost-system-dev libboost-test-dev
  libgtest-dev googletest sqlite3 python3 python3-numpy nlohmann-json3-dev libyaml-cpp-dev
  ccache
  # scripts/fuzz.sh: clang (14 in bookworm), the runtimes of libFuzzer and
  # the sanitizers, and clang's OpenMP (COLMAP's headers need OpenMP).
  clang libclang-rt-14-dev libomp-14-dev
  # The report's browser test (ctest -R report_browser): headless Chromium
  # and a font for its text.
  chromium fonts-dejavu-core
)

missing_packages() {
  local p
  for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || echo "$p"
  done
}

if [ "${RIG_CALIBRATOR_SKIP_APT:-0}" != 1 ]; then
  mapfile -t missing < <(missing_packages)
  if [ "${#missing[@]}" -gt 0 ]; then
    say "installing ${#missing[@]} Debian packages: ${missing[*]}"
    export DEBIAN_FRONTEND=noninteractive
    mkdir -p "$cache"
    apt_log="$cache/apt-install.log"
    "${sudo_cmd[@]}" apt-get update -qq > "$apt_log" 2>&1 \
      || { tail -n 20 "$apt_log"; die "apt-get update failed (network or package sources?)."; }
    "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >> "$apt_log" 2>&1 \
      || { tail -n 20 "$apt_log"; die "apt-get install failed for: ${missing[*]} (log: $apt_log)"; }
  else
    say "all Debian packages present"
  fi
fi

for tool in g++ cmake ninja; do
  command -v "$tool" >/dev/null 2>&1 || die "'$tool' not found after installing packages."
done

# COLMAP's source tree stays in the cache after the build: the project's
# `colmap` executable compiles COLMAP's own command sources (src/exe) from it.
src_root="$cache/src"
src="$src_root/colmap-3.8"
fetch_colmap_source() {
  [ -f "$src/src/exe/colmap.cc" ] && return 0
  say "unpacking COLMAP 3.8's source (Debian's source package) into $src_root"
  mkdir -p "$src_root" "$cache/apt/lists/partial"
  cat > "$cache/apt/sources.list" <<SRC
deb-src http://deb.debian.org/debian bookworm main
SRC
  local apt_opts=(-o "Dir::Etc::SourceList=$cache/apt/sources.list" -o "Dir::Etc::SourceParts=/dev/null"
                  -o "Dir::State::Lists=$cache/apt/lists")
  apt-get "${apt_opts[@]}" update -qq > "$cache/apt-source.log" 2>&1 \
    || { tail -n 20 "$cache/apt-source.log"; die "could not read the bookworm deb-src index."; }
  (cd "$src_root" && apt-get "${apt_opts[@]}" source -qq colmap=3.8-1) >> "$cache/apt-source.log" 2>&1 \
    || { tail -n 20 "$cache/apt-source.log"; die "apt-get source colmap=3.8-1 failed."; }
  [ -f "$src/CMakeLists.txt" ] && [ -f "$src/src/exe/colmap.cc" ] \
    || die "COLMAP source not found in $src."
}

if [ -f "$stamp" ] && [ -x "$prefix/bin/colmap" ] && [ -f "$prefix/share/colmap/COLMAPConfig.cmake" ]; then
  fetch_colmap_source
  say "COLMAP 3.8 found in cache $prefix (source in $src): skipping its build"
  exit 0
fi

say "building COLMAP 3.8 from Debian's source package into $prefix (about 9 minutes on 2 cores)"
fetch_colmap_source

# Ninja compiles the objects of COLMAP's libraries in any order (Make waits for
# each library before the next one's objects), which keeps both cores busy.
build="$src/build-rig-calibrator"
# A folder left by an unfinished build with another generator starts afresh.
grep -qs '^CMAKE_GENERATOR:INTERNAL=Ninja$' "$build/CMakeCache.txt" || rm -rf "$build"
mkdir -p "$build"
cmake -S "$src" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX="$prefix" \
  -DGUI_ENABLED=OFF -DOPENGL_ENABLED=OFF -DCUDA_ENABLED=OFF -DCGAL_ENABLED=OFF \
  -DIPO_ENABLED=OFF -DBOOST_STATIC=OFF -DTESTS_ENABLED=OFF > "$build/configure.log" 2>&1 \
  || { tail -n 30 "$build/configure.log"; die "configuring COLMAP failed (log: $build/configure.log)."; }
cmake --build "$build" -j"$jobs" --target install > "$build/build.log" 2>&1 \
  || { tail -n 40 "$build/build.log"; die "building COLMAP failed (log: $build/build.log)."; }
"$prefix/bin/colmap" help > /dev/null 2>&1 || die "the freshly built colmap does not run."
date -u +%FT%TZ > "$stamp"
say "COLMAP 3.8 installed in $prefix"
