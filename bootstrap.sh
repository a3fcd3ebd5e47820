#!/usr/bin/env bash
# kushner bootstrap: installs what the build needs, builds, and runs.
#
#   ./bootstrap.sh run [kushner args...]  build, then run kushner (no arguments: the main job on defaults)
#   ./bootstrap.sh test                   build, then run the whole test suite (ctest)
#   ./bootstrap.sh build                  dependencies + Release build in build/
#   ./bootstrap.sh deps                   dependencies only
#   ./bootstrap.sh bundle                 also copy header-only libraries and test/benchmark sources into
#                                         .deps/ so that a machine with no package registry can build
#
# Idempotent: every step checks what is already there and skips it. Everything fetched lives in .deps/
# (git-ignored). Kokkos 3.4.01 comes from Debian's `trilinos` source package (see README, "Dependencies").
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
deps="$here/.deps"
build_dir="${KUSHNER_BUILD_DIR:-$here/build}"
jobs="${KUSHNER_JOBS:-$(nproc)}"

say() { printf 'bootstrap: %s\n' "$*" >&2; }
die() { printf 'bootstrap: error: %s\n' "$*" >&2; exit 1; }

as_root() {
  if [ "$(id -u)" -eq 0 ]; then "$@"; elif command -v sudo >/dev/null; then sudo "$@"; else
    die "need root (or sudo) to run: $*"; fi
}

debian_packages=(g++ cmake make patch dpkg-dev clang-format libeigen3-dev libcli11-dev librandom123-dev nlohmann-json3-dev
                 libtomlplusplus-dev googletest libgtest-dev libbenchmark-dev python3 python3-numpy python3-matplotlib
                 libopenmpi-dev openmpi-bin)

install_packages() {
  command -v dpkg-query >/dev/null || { say "not a Debian system: install ${debian_packages[*]} by hand"; return; }
  local missing=()
  for p in "${debian_packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return
  say "installing Debian packages: ${missing[*]}"
  as_root apt-get update -qq
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

# `apt-get source` needs deb-src entries: derive them from the machine's own binary sources, so no host is
# named here and the snapshot/mirror the machine already uses is kept.
enable_deb_src() {
  local list=/etc/apt/sources.list.d/kushner-deb-src.sources
  [ -f "$list" ] || [ -f "${list%.sources}.list" ] && return
  local src=/etc/apt/sources.list.d/debian.sources
  if [ -f "$src" ]; then
    say "enabling deb-src entries ($list)"
    sed 's/^Types: deb$/Types: deb-src/' "$src" | as_root tee "$list" >/dev/null
  elif [ -f /etc/apt/sources.list ] && grep -q '^deb ' /etc/apt/sources.list; then
    list=/etc/apt/sources.list.d/kushner-deb-src.list
    say "enabling deb-src entries ($list)"
    sed -n 's/^deb /deb-src /p' /etc/apt/sources.list | as_root tee "$list" >/dev/null
  else
    die "no apt sources to derive deb-src entries from; add deb-src lines for trilinos by hand"
  fi
  as_root apt-get update -qq
}

# Fetch a Debian source package into .deps/download (once).
fetch_source() {
  local pkg=$1 pattern=$2
  mkdir -p "$deps/download"
  if ! ls "$deps/download"/$pattern >/dev/null 2>&1; then
    enable_deb_src
    say "fetching Debian source package $pkg"
    (cd "$deps/download" && apt-get source --download-only "$pkg" >/dev/null 2>&1) ||
      die "apt-get source $pkg failed (are deb-src entries reachable?)"
  fi
}

install_kokkos_source() {
  [ -f "$deps/kokkos/.kushner-patched" ] && return
  fetch_source trilinos 'trilinos_*.orig.tar.*'
  say "extracting packages/kokkos from the trilinos source"
  rm -rf "$deps/kokkos" "$deps/kokkos.tmp" && mkdir -p "$deps/kokkos.tmp"
  tar -xf "$deps"/download/trilinos_*.orig.tar.* -C "$deps/kokkos.tmp" --strip-components=2 --wildcards '*/packages/kokkos/*'
  mv "$deps/kokkos.tmp/kokkos" "$deps/kokkos" && rm -rf "$deps/kokkos.tmp"
  # Three changes for CUDA 13 on Hopper (TOOLCHAIN.md); harmless for OpenMP/Serial builds.
  patch -d "$deps/kokkos" -p1 --forward --quiet < "$here/cmake/kokkos-3.4.01-cuda13.patch"
  touch "$deps/kokkos/.kushner-patched"
  rm -f "$deps"/download/trilinos_*  # 166 MB; only packages/kokkos is kept
}

# For machines with no package registry (the GPU machine): header-only libraries and the sources of
# GoogleTest and Google Benchmark, which CMake uses when find_package finds nothing installed.
bundle() {
  mkdir -p "$deps/include"
  [ -d "$deps/include/Eigen" ] || cp -r /usr/include/eigen3/Eigen /usr/include/eigen3/unsupported "$deps/include/"
  [ -d "$deps/include/CLI" ] || cp -r /usr/include/CLI "$deps/include/"
  [ -d "$deps/include/Random123" ] || cp -r /usr/include/Random123 "$deps/include/"
  [ -d "$deps/include/nlohmann" ] || cp -r /usr/include/nlohmann "$deps/include/"
  [ -d "$deps/include/toml++" ] || cp -r /usr/include/toml++ "$deps/include/"
  [ -d "$deps/googletest" ] || cp -r /usr/src/googletest "$deps/googletest"
  if [ ! -d "$deps/benchmark" ]; then
    fetch_source benchmark 'benchmark_*.orig.tar.*'
    mkdir -p "$deps/benchmark" && tar -xf "$deps"/download/benchmark_*.orig.tar.* -C "$deps/benchmark" --strip-components=1
  fi
}

configure_and_build() {
  if [ ! -f "$build_dir/CMakeCache.txt" ]; then
    say "configuring $build_dir (Release, OpenMP)"
    cmake -S "$here" -B "$build_dir" -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
  fi
  say "building with $jobs jobs"
  cmake --build "$build_dir" -j "$jobs"
}

cmd=${1:-run}
[ $# -gt 0 ] && shift
case "$cmd" in
  deps) install_packages; install_kokkos_source ;;
  bundle) install_packages; install_kokkos_source; bundle ;;
  build) install_packages; install_kokkos_source; configure_and_build "$@" ;;
  test)
    install_packages; install_kokkos_source; configure_and_build
    cd "$build_dir" && OMP_PROC_BIND=false ctest --output-on-failure -j "$jobs" "$@" ;;
  run)
    install_packages; install_kokkos_source; configure_and_build >&2
    if [ $# -eq 0 ]; then set -- compare --out kushner-out; fi
    exec "$build_dir/kushner" "$@" ;;
  *) die "unknown command '$cmd' (known: run, test, build, deps, bundle)" ;;
esac
