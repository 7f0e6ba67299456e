#!/usr/bin/env bash
# Configures and builds pneumo in Release into build/ (or $PNEUMO_BUILD_DIR). Idempotent.
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${PNEUMO_BUILD_DIR:-build}
jobs=${PNEUMO_JOBS:-$(nproc)}
cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
cmake --build "$build_dir" --parallel "$jobs"
