#!/usr/bin/env bash
# pneumo's image warp against VTK's and ITK's, voxel by voxel, on the peers' phantom, mesh and deformation
# (../shared/peers: phantom.py, vtk_tetwarp.py, itk_warp.cxx). compare_warp.py says what is compared and where.
#
#   bash bench/peers/compare_warp.sh WORKDIR     # ~5 min on 2 cores, ~3 GB of volumes in WORKDIR
#
# Results: WORKDIR/compare_warp.{json,md}, the values voxel by voxel and the speeds measured in this run (VTK's
# pipeline, ITK's resampling, pneumo's warp, medians of 3 where the tool repeats); the volumes stay in WORKDIR for
# a look (3D Slicer opens .mhd).
set -euo pipefail
cd "$(dirname "$0")/../.."
work=${1:?usage: bash bench/peers/compare_warp.sh WORKDIR}
peers=${PNEUMO_PEERS_DIR:-$PWD/../shared/peers}
[ -f "$peers/vtk_tetwarp.py" ] || { echo "compare_warp: no peers in $peers (set PNEUMO_PEERS_DIR)" >&2; exit 2; }
py=/usr/bin/python3   # Debian's interpreter: python3-vtk9 and python3-scipy are installed for it only

bash scripts/install_deps.sh --peers
bash scripts/build.sh
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$PWD/build/pocl-cache}
mkdir -p "$work" "$POCL_CACHE_DIR"
work=$(cd "$work" && pwd)

[ -f "$work/phantom.mhd" ] || "$py" "$peers/phantom.py" "$work"
echo "compare_warp: VTK (vtkProbeFilter pull-back, ~80 s)" >&2
rm -f "$work/vtk_tetwarp.jsonl"
"$py" "$peers/vtk_tetwarp.py" "$work" --resample mapcoords,reslice --write-field --write-warped \
  --log "$work/vtk_tetwarp.jsonl"
cmake -S "$peers" -B "$work/itk-build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/itk-build" --target itk_warp >/dev/null
# Each timed tool starts with the previous one's files on disk (sync), so none pays for another's writeback.
sync
echo "compare_warp: pneumo on the same mesh and lift" >&2
build/pneumo bench --peer-warp "$work" --repeats 3 > "$work/pneumo_peer_warp.json"
sync
echo "compare_warp: ITK through VTK's field and through pneumo's" >&2
"$work/itk-build/itk_warp" "$work/phantom.mhd" "$work/disp.mhd" --out "$work/warped_itk.mhd" --repeats 3 |
  tee "$work/itk_warp.txt"
"$work/itk-build/itk_warp" "$work/phantom.mhd" "$work/pneumo/disp_pneumo.mhd" \
  --out "$work/warped_itk_pneumo_field.mhd" --repeats 1
"$py" bench/peers/compare_warp.py "$work" "$peers" --json "$work/compare_warp.json" --markdown "$work/compare_warp.md"
