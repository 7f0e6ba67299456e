#!/usr/bin/env bash
# README's second command: installs every dependency, builds, and runs the whole test suite
# through CTest. Tests that read the real CT expect ../shared beside the repository.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
bash scripts/build.sh
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$PWD/build/pocl-cache}
mkdir -p "$POCL_CACHE_DIR"
ctest --test-dir build --output-on-failure --parallel "${PNEUMO_JOBS:-$(nproc)}" "$@"
