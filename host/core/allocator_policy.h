#pragma once
// How the process's allocator treats large blocks. glibc maps every block over its mmap threshold
// (at most 32 MiB) afresh and unmaps it on free, so each stage's volumes (10⁸ voxels on a 0.75 mm CT:
// copies, filter passes, gradients, the warp's grids) arrive as new pages the kernel must zero:
// clear_page was 27 % of the large phantom's run. Served from the heap instead, and kept there when
// freed, a block is reused by the next stage without a page fault.
namespace pneumo {

/// Large allocations from the heap (M_MMAP_MAX 0) and freed memory kept for reuse up to 2 GiB at
/// the heap's top (M_TRIM_THRESHOLD). The process's peak is then what it holds until it exits:
/// measured +4 % on the large phantom (bench/results/2026-12-06-allocator.md). Called once, first
/// thing in main().
void keep_freed_memory_for_reuse();

}  // namespace pneumo
