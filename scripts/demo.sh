#!/usr/bin/env bash
# README's first command: installs every dependency, builds, and runs the main job on the embedded
# default case (the synthetic abdomen), leaving its outputs in out/demo.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
bash scripts/build.sh
out=${1:-out/demo}
./build/pneumo phantom --size small --out "$out" --force
./build/pneumo info "$out/ct.nii.gz"
./build/pneumo info "$out/labels.nii.gz"
./build/pneumo scene "$out/scene.json" >/dev/null && echo "scene: $out/scene.json is valid"
./build/pneumo devices
echo "demo: outputs in $out"
