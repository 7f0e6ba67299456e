#!/usr/bin/env bash
# Fuzzes the NIfTI, MetaImage and NRRD readers and the scene parser with libFuzzer: installs
# the project's dependencies plus clang and its fuzzer runtime (kept out of install_deps.sh so the
# usual build stays lean), configures a clang build with -DPNEUMO_FUZZ=ON in build-fuzz/, and runs
# the tests labelled "fuzz", each for PNEUMO_FUZZ_SECONDS (default 60). Idempotent.
# A crash stops its test; the input is in build-fuzz/tests/fuzz/crashes/<target>/ and can be
# replayed with build-fuzz/tests/fuzz/fuzz_<target> FILE. Turn each into a test in
# tests/test_fuzz_regressions.cpp.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
extras=(clang-14 libclang-rt-14-dev)
missing=()
for p in "${extras[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""; if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
build_dir=${PNEUMO_FUZZ_BUILD_DIR:-build-fuzz}
CC=clang-14 CXX=clang++-14 cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DPNEUMO_FUZZ=ON -DPNEUMO_FUZZ_SECONDS="${PNEUMO_FUZZ_SECONDS:-60}" >/dev/null
cmake --build "$build_dir" --parallel "${PNEUMO_JOBS:-$(nproc)}"
ctest --test-dir "$build_dir" -L fuzz --output-on-failure "$@"
