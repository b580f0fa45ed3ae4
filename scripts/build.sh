#!/bin/sh
# Configure and build with CMake into ./build (Release with debug info).
# Extra arguments go to the configure step, e.g. -DMILL_SANITIZE=ON.
set -eu
cd "$(dirname "$0")/.."
BUILD_DIR="${BUILD_DIR:-build}"
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=RelWithDebInfo "$@" >/dev/null
cmake --build "$BUILD_DIR" -j"$(nproc)"
echo "build: programs in $BUILD_DIR/bin/ (orchestrate, liggghts-mill)"
