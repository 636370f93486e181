#!/usr/bin/env bash
# Installs every dependency of DeformKit from Debian 12 packages (skipping what is installed), then
# configures and builds a Release build in ./build. Safe to run again: it only does what is missing.
#
#   ./scripts/setup.sh            install + configure + build
#   ./scripts/setup.sh --deps     install only
#   ./scripts/setup.sh --with-sanitized-tests    also build the sanitized unit tests (scripts/test.sh)
#   ./scripts/setup.sh --sanitized-tests-only    only those (scripts/test.sh --sanitize)
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
    build-essential cmake ninja-build pkg-config git
    lld                              # LLVM's linker: links in a sixth of GNU ld's time
    clang-format                     # the formatting check (tests/format)
    libosd-dev                       # OpenSubdiv
    libopenimageio-dev openimageio-tools
    libopenexr-dev libimath-dev      # OpenEXR
    libglm-dev libeigen3-dev
    catch2 libbenchmark-dev
    libomp-dev zlib1g-dev
    libcli11-dev nlohmann-json3-dev
    libassimp-dev                    # glTF, FBX, PLY and Collada meshes
    python3 python3-dev pybind11-dev python3-numpy python3-pytest
    clang libclang-rt-14-dev         # libFuzzer and sanitizers
    g++-aarch64-linux-gnu            # tests/build: the SIMD sources compile for a non-x86 target
    slurm-wlm munge                  # farm tests: single-node Slurm
    blender                          # the Blender add-on's tests (headless Blender 3.4)
    chromium                         # the shot report's test opens the page in a real browser
    assimp-testmodels                # OBJ files as exporters write them (another library's test models)
)

missing=()
for p in "${packages[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
        missing+=("$p")
    fi
done
if ((${#missing[@]})); then
    echo "setup: installing ${missing[*]}"
    sudo=""
    if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
else
    echo "setup: every dependency is installed"
fi

if [ "${1:-}" = "--deps" ]; then exit 0; fi
targets=()
case "${1:-}" in
    --with-sanitized-tests) targets=(--target all deformkit_sanitized_tests) ;;
    --sanitized-tests-only) targets=(--target deformkit_sanitized_tests) ;;
esac

jobs=$(nproc 2>/dev/null || echo 2)
# Build the Python module for Debian's own interpreter (the one Blender embeds), whatever python3
# comes first on PATH.
# Ninja for a new build folder (it keeps both cores busy across targets); an existing one keeps its generator.
generator=()
if [ ! -f build/CMakeCache.txt ] && command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
cmake -S . -B build "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DPython_EXECUTABLE=/usr/bin/python3 >/dev/null
cmake --build build -j "$jobs" "${targets[@]}"
echo "setup: built into ./build (CLI: ./build/bin/deformkit, Python module: ./build/python)"
