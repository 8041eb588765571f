#!/usr/bin/env bash
# Installs, builds and runs every test (ctest). The README's test command; .ci/run calls it.
set -euo pipefail
cd "$(dirname "$0")/.."
# CI builds with -Werror (FEEDDRIVE_WERROR; off by default for packagers with newer compilers).
bash scripts/build.sh -DFEEDDRIVE_WERROR=ON
# The tree is formatted by .clang-format (clang-format comes with scripts/install-deps.sh, which
# build.sh ran).
bash scripts/format-check.sh
BUILD_DIR=${BUILD_DIR:-build}
ctest --test-dir "$BUILD_DIR" --output-on-failure -j"$(nproc)" --timeout 1200
