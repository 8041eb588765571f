#!/usr/bin/env bash
# Installs the dependencies (scripts/install-deps.sh) and builds feeddrive into ${BUILD_DIR:-build}.
# Arguments go to the configure step, e.g. -DFEEDDRIVE_WERROR=ON (README.md, "Build options").
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
BUILD_DIR=${BUILD_DIR:-build}
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release "$@"
cmake --build "$BUILD_DIR" -j"$(nproc)"
