// The process's allocator settings for the solves (glibc's malloc).
#pragma once

namespace varia::host {

// Eigen's SparseLU allocates its workspaces (a few hundred KB for a system of a few thousand
// unknowns) at every factorization and frees them at its end; glibc hands such blocks back to the
// kernel (they are mmapped, or trimmed from the heap's top) and faults them in again at the next
// one, which made the constrained rod chain's step 3x slower than linear in the chain's length at
// 512 particles (docs/constraints.md, "Measured"). This keeps freed memory in the process: blocks
// up to 32 MB come from the heap, and the heap is trimmed only above 256 MB free.
void keep_freed_memory();

}  // namespace varia::host
