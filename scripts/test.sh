#!/bin/sh
# Build and run the whole test suite (CTest + GoogleTest), then the unit tests
# again under AddressSanitizer + UndefinedBehaviorSanitizer (project code).
set -eu
cd "$(dirname "$0")/.."
./scripts/build.sh -DMILL_WERROR=ON
ctest --test-dir build --output-on-failure -j2 --timeout 1500
# (no -Werror here: GCC 12 gives false maybe-uninitialized warnings in
# libstdc++ under ASan; the build above already enforces warning-free code)
BUILD_DIR=build-sanitize ./scripts/build.sh -DMILL_SANITIZE=ON -DMILL_WERROR=OFF -DMILL_WITH_STYLES=OFF
ASAN_OPTIONS=detect_leaks=1 ctest --test-dir build-sanitize --output-on-failure -j2 -L unit --timeout 600
