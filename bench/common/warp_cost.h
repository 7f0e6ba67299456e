#pragma once
// DRAM bytes per output voxel of the image warp (method.md §7), counted from the data: the denominator of the
// warp's roofline ratio, shared by bench_warp.cpp and `pneumo bench`.
//
// The source CT (float32), roles (1 B) and labels (2 B) are read about once (a smooth deformation reads each source
// voxel about once; the padding the roles added is read only where mapped), the CT (4 B), labels (2 B) and outcome
// (1 B) written once; OpenCL adds the owner buffer (4 B written by the fill, read by the scatter's check and the
// sample pass: 12 B) and the host↔device copies (source 7 B, results 7 B, each read and written: 28 B).
namespace pneumo::bench {

constexpr double kWarpCpuBytesPerVoxel = 4 + 1 + 2 + 4 + 2 + 1;
constexpr double kWarpClBytesPerVoxel = kWarpCpuBytesPerVoxel + 12 + 28;

// Peers measured on the project's reference machine (AMD EPYC Zen 4, 2 cores: ../shared/peers/RESULTS-2026-11.md), for
// the x_vtk and x_itk ratios: a guide on that machine only. Elsewhere compare with bench/peers/compare_warp.sh, which
// times the peers and pneumo in one run on the same case.
constexpr double kVtkWarpVoxelsPerS = 1.04e6;   // warp_probe probe_mvox_per_s (vtkProbeFilter pull-back)
constexpr double kItkWarpVoxelsPerS = 29.5e6;   // itk_double_file mvox_per_s_median (2 threads)

}  // namespace pneumo::bench
