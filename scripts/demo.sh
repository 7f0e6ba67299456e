#!/usr/bin/env bash
# README's first command: installs every dependency, builds, and runs the main job on the embedded
# default case (the synthetic abdomen): phantom → roles → mesh → inflation at 12 mmHg → warped CT.
# Outputs land in out/demo (or the folder given as the first argument).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
bash scripts/build.sh
out=${1:-out/demo}
./build/pneumo devices
./build/pneumo phantom --size small --out "$out" --force
./build/pneumo roles "$out/scene.json" --png "$out/roles.png"
./build/pneumo simulate "$out/scene.json" --out "$out" --force
./build/pneumo warp "$out/scene.json" --out "$out" --force
echo "demo: outputs in $out (roles.png, mesh_initial.vtu, mesh_deformed.vtu for ParaView, deformed_ct.nii.gz,"
echo "      deformed_labels.nii.gz for 3D Slicer or ITK-SNAP, slices_before_after.png, metrics.json)"
