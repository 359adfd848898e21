#!/usr/bin/env bash
# Installs what lmbake needs (Debian packages; later npm pieces), only what is missing,
# then configures and builds one build tree. Idempotent and quiet when nothing is missing.
#   usage: tools/setup.sh [BUILD_DIR] [extra cmake args...]   (default: build, Release)
#   LMB_SETUP_PACKAGES: more Debian packages a caller needs (tools/fuzz.sh: clang-14, libFuzzer)
#   LMB_BUILD_TARGETS: build only these targets (default: all)
set -euo pipefail
cd "$(dirname "$0")/.."

build_dir=${1:-build}
shift || true

# Why each is here: README.md "Dependencies".
packages=(
  build-essential cmake pkg-config  # compiler, build
  libyaml-dev                       # bake config (YAML with line numbers for errors)
  libtinygltf-dev                   # glTF 2.0 reading and writing
  libmeshoptimizer-dev libdraco-dev # decoding EXT_meshopt_compression and KHR_draco_mesh_compression (gltfpack, glTF-Transform)
  libcjson-dev                      # glTF JSON preflight (version, required extensions, compression)
  nettle-dev                        # SHA-256 of the staged bake's plan and part files
  libzstd-dev                       # Zstandard supercompression of KTX2 lightmaps
  libastcenc-dev astcenc            # ASTC HDR lightmaps (Arm's encoder) and the tests' independent ASTC decoder
  libembree-dev libtbb-dev          # ray tracing (Embree's CMake config needs TBB)
  libopenimageio-dev openimageio-tools  # reading textures and sky images, other formats (OIIO's CMake config wants the tools)
  libopenexr-dev libimath-dev       # .exr lightmaps through OpenEXRCore (C), half floats (Imath's C half.h)
  libpng-dev libstb-dev             # .png (libpng) and .hdr (stb_image_write) lightmaps, without loading OIIO
  libopenmesh-dev                   # the unwrapper's half-edge mesh (OpenMesh, behind baker/unwrap/halfedge_adapter.cpp)
  libsuitesparse-dev                # CHOLMOD sparse Cholesky for the LSCM flattening
  libqhull-dev                      # the light probes' Delaunay tetrahedra (qhull's reentrant C API)
  python3-matplotlib python3-openimageio  # benchmark plots, reading EXR in test scripts
  chromium                          # headless browser for the preview's shots and e2e test (playwright-core drives it)
  strace                            # the hostile-input test checks which files a bake opens
  parallel                          # GNU parallel: 'lmbake farm parallel' and its test
)

read -r -a extra <<<"${LMB_SETUP_PACKAGES:-}"
packages+=("${extra[@]}")

# node and npm: the machine's own if it has them, else Debian's
command -v npm >/dev/null || packages+=(nodejs npm)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${#missing[@]} missing Debian package(s): ${missing[*]}"
  sudo=""
  [ "$(id -u)" = 0 ] || sudo="sudo"
  log=$(mktemp)
  if ! { $sudo apt-get update -qq && DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"; } >"$log" 2>&1; then
    tail -n 30 "$log"; echo "setup: apt-get failed (full log: $log)"; exit 1
  fi
  rm -f "$log"
fi

# npm pieces (package.json): the Khronos glTF validator and ktx-parse (an independent KTX2 reader) for the
# tests, three.js and playwright-core for the preview, xatlasjs for the unwrap benchmark, glTF-Transform's
# CLI and gltfpack for the optimised-level test's inputs, Babylon.js for lmbake-babylon's test, lmbake-probes
# (loaders/probes, linked) for the engine modules
if [ ! -d node_modules/gltf-validator ] || [ ! -d node_modules/three ] || [ ! -d node_modules/playwright-core ] || [ ! -d node_modules/ktx-parse ] || [ ! -d node_modules/xatlasjs ] || [ ! -d node_modules/@gltf-transform/cli ] || [ ! -d node_modules/gltfpack ] || [ ! -d node_modules/@babylonjs/core ] || [ ! -d node_modules/@babylonjs/loaders ] || [ ! -e node_modules/lmbake-probes ]; then
  echo "setup: installing npm packages (package.json)"
  npm install --no-audit --no-fund --silent >/dev/null 2>&1 || { echo "setup: npm install failed"; exit 1; }
fi

log="$build_dir/setup.log"
mkdir -p "$build_dir"
if ! cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release "$@" >"$log" 2>&1; then
  cat "$log"; echo "setup: cmake configure failed"; exit 1
fi
targets=()
for t in ${LMB_BUILD_TARGETS:-}; do targets+=(--target "$t"); done
if ! cmake --build "$build_dir" -j"$(nproc)" "${targets[@]}" >>"$log" 2>&1; then
  grep -E "error|Error" "$log" | head -n 40; echo "setup: build failed (full log: $log)"; exit 1
fi
if grep -q "warning:" "$log"; then
  echo "setup: the build printed warnings (see $log)"
fi
