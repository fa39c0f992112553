#!/usr/bin/env bash
# Installs everything rig_calibrator needs on Debian 12 (bookworm) and builds COLMAP 3.8's
# libraries, headers and command-line tool from Debian's source package into a cache prefix
# outside the repository ($cache/colmap-3.8). Beside COLMAP's own files the prefix gets
# lib/colmap/libcolmap_commands.a: the objects COLMAP compiled for its command line (src/exe),
# with colmap.cc's `main` renamed `ColmapMain`, from which the project's extended `colmap` is
# linked. Idempotent: a rerun with the cache in place skips the COLMAP build; a cache made
# before that archive existed gets it from COLMAP's build folder, or is built again.
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
  build-essential binutils cmake ninja-build git pkg-config dpkg-dev ca-certificates
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

# COLMAP's source tree, unpacked into the cache; its build folder inside it.
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

# The build folder stays in the cache: its src/exe objects make the archive
# below.
build="$src/build-rig-calibrator"
commands_archive="$prefix/lib/colmap/libcolmap_commands.a"
exe_objects="$build/src/exe/CMakeFiles/colmap_exe.dir"
# The sources of COLMAP's command line other than feature.cc and sfm.cc, which
# libcolmap.a already holds (COLMAP_ADD_SOURCES in its src/exe/CMakeLists.txt).
command_sources=(colmap database gui image model mvs vocab_tree)

# libcolmap_commands.a from the objects of COLMAP's own `colmap`: compiled once,
# by COLMAP's build with COLMAP's flags, instead of again by the project's.
# colmap.cc's `main` becomes `ColmapMain` (colmap_ext/commands/colmap_main.cc
# calls it). False when the objects are gone.
archive_colmap_commands() {
  local work="$build/rig_calibrator_commands" name objects=()
  for name in "${command_sources[@]}"; do
    [ -f "$exe_objects/$name.cc.o" ] || return 1
  done
  rm -rf "$work"
  mkdir -p "$work"
  for name in "${command_sources[@]}"; do
    cp "$exe_objects/$name.cc.o" "$work/colmap_$name.o"
    objects+=("$work/colmap_$name.o")
  done
  objcopy --redefine-sym main=ColmapMain "$work/colmap_colmap.o" \
    || die "objcopy could not rename main in $exe_objects/colmap.cc.o."
  # (grep without -q reads all of nm's output: with pipefail, nm killed by
  # SIGPIPE after an early match would fail the check.)
  nm "$work/colmap_colmap.o" | grep ' T ColmapMain$' > /dev/null \
    || die "no ColmapMain in $work/colmap_colmap.o after renaming main."
  rm -f "$commands_archive.tmp"
  ar rcs "$commands_archive.tmp" "${objects[@]}" && mv "$commands_archive.tmp" "$commands_archive"
  rm -rf "$work"
}

if [ -f "$stamp" ] && [ -x "$prefix/bin/colmap" ] && [ -f "$prefix/share/colmap/COLMAPConfig.cmake" ]; then
  if [ -f "$commands_archive" ]; then
    say "COLMAP 3.8 found in cache $prefix: skipping its build"
    exit 0
  fi
  if archive_colmap_commands; then
    say "COLMAP 3.8 found in cache $prefix: archived its command objects in $commands_archive"
    exit 0
  fi
  say "the cache $prefix has no $commands_archive and COLMAP's objects are gone: building again"
  rm -f "$stamp"
fi

say "building COLMAP 3.8 from Debian's source package into $prefix (about 7 minutes on 2 cores)"
fetch_colmap_source

# COLMAP's own `colmap` compiles feature.cc and sfm.cc a second time, though
# its library holds them (COLMAP_ADD_SOURCES in src/exe/CMakeLists.txt): the
# executable takes them from libcolmap.a instead, the same code compiled once
# (about 50 s of CPU).
exe_cmake="$src/src/exe/CMakeLists.txt"
sed -i '/^COLMAP_ADD_EXECUTABLE(colmap_exe$/,/)$/{/^ *\(feature\|sfm\)\.cc$/d}' "$exe_cmake"
exe_sources="$(sed -n '/^COLMAP_ADD_EXECUTABLE(colmap_exe$/,/)$/p' "$exe_cmake")"
if grep -q '^ *\(feature\|sfm\)\.cc$' <<< "$exe_sources" ||
  ! grep -q '^ *colmap\.cc$' <<< "$exe_sources"; then
  die "unexpected COLMAP_ADD_EXECUTABLE(colmap_exe ...) in $exe_cmake."
fi

# The Poisson surface reconstruction (`colmap poisson_mesher`, dense meshing,
# no part of a calibration) is one file that takes 105 s of CPU at -O3 and
# 28 s at -O1 (g++ 12, COLMAP's flags): it is compiled at -O1 (a later -O
# wins; the source's options come after the build type's flags).
poisson_cmake="$src/lib/PoissonRecon/CMakeLists.txt"
grep -q 'PoissonRecon.cpp PROPERTIES COMPILE_OPTIONS -O1' "$poisson_cmake" ||
  printf '\nset_source_files_properties(PoissonRecon.cpp PROPERTIES COMPILE_OPTIONS -O1)\n' \
    >> "$poisson_cmake"

# Ninja compiles the objects of COLMAP's libraries in any order (Make waits for
# each library before the next one's objects), which keeps both cores busy.
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
archive_colmap_commands || die "COLMAP's command objects are missing in $exe_objects."
date -u +%FT%TZ > "$stamp"
say "COLMAP 3.8 installed in $prefix"
