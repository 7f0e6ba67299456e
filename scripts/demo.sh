#!/usr/bin/env bash
# README's first command: installs every dependency, builds, and runs the main job on the embedded
# default case (the synthetic abdomen, medium size): phantom → roles → mesh → inflation at 12 mmHg →
# warped CT → laparoscope views from two ports, a camera and a fly-through → report.html.
# Outputs land in out/demo (or the folder given as the first argument).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
bash scripts/build.sh
out=${1:-out/demo}
./build/pneumo devices
./build/pneumo phantom --size medium --out out/phantom_medium --force
./build/pneumo run scenes/phantom_ports_flythrough.json --out "$out" --force
echo "demo: open $out/report.html (offline, self-contained). Beside it: views/*.png (ports, camera, exterior),"
echo "      flythrough/, slices_before_after.png, deformed_ct.nii.gz and deformed_labels.nii.gz (3D Slicer,"
echo "      ITK-SNAP), mesh_initial.vtu and mesh_deformed.vtu (ParaView), metrics.json, convergence.svg"
