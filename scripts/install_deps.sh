#!/usr/bin/env bash
# Installs every build and run dependency of pneumo from Debian 12 packages.
# Idempotent and non-interactive; run as root (or with sudo available).
#   --peers  also what the peer tools need beyond the tests' set, for bench/peers/: SciPy, GLEW, and Xvfb
#            (VTK's offscreen window on Debian's build needs an X server: vtk_view_resolution.py).
set -euo pipefail

packages=(
  # toolchain
  build-essential cmake ninja-build pkg-config git ca-certificates
  # OpenCL: PoCL on the CPU, the ICD loader, C and C++ headers, clinfo to look
  pocl-opencl-icd ocl-icd-opencl-dev opencl-headers opencl-clhpp-headers clinfo
  # maths
  libeigen3-dev
  # offscreen OpenGL: EGL (primary), OSMesa (fallback), GL headers
  libegl-dev libgl-dev libopengl-dev libgles-dev libosmesa6-dev libegl-mesa0 mesa-utils
  # image output; ffmpeg (with ffprobe) encodes the fly-through and inflation-preview MP4s
  libstb-dev ffmpeg
  # volume I/O; HDF5 writes the ITK transform file of the displacement field, GDCM reads DICOM
  # series, teem reads and writes NRRD, libdeflate compresses .nii.gz on every core
  libnifti2-dev zlib1g-dev libdeflate-dev libhdf5-dev libgdcm-dev libteem-dev
  # CLI and scenes
  libcli11-dev nlohmann-json3-dev
  # `pneumo serve`: cpp-httplib serves the page; the browser test drives Chromium through Selenium
  libcpp-httplib-dev chromium-driver python3-selenium
  # tests and benchmarks; VTK's Python reader checks the meshes pneumo writes (tests/test_vtu_vtk.cpp),
  # ITK applies the displacement field pneumo writes and nibabel reads it (tests/test_displacement_field.cpp),
  # pydicom writes the DICOM series pneumo reads (tests/test_dicom_series.cpp)
  libgtest-dev googletest libbenchmark-dev python3-vtk9 python3-numpy python3-nibabel python3-pydicom libinsighttoolkit5-dev
  # headless Chromium loads report.html and takes a screenshot of it (tests/test_report_browser.cpp)
  chromium
  # cohorts and sweeps (workflow/Snakefile, tests/test_workflow.cpp): Snakemake runs them, matplotlib draws
  # the gathered figure
  snakemake python3-matplotlib
)
if [ "${1:-}" = "--peers" ]; then
  packages+=(python3-scipy libglew-dev xvfb xauth)
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install_deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
