// Process-wide settings that a settle's speed depends on, applied once on
// the first settle (static or explicit).
#pragma once

namespace hj {

// - OpenBLAS (when it is the system BLAS under UMFPACK) to one thread: it
//   would otherwise spin threads on sparse fronts far too small to share.
// - glibc malloc keeps freed blocks for reuse instead of returning each
//   large one to the kernel: a settle allocates and frees the same
//   100 kB - 1 MB arrays every step (matrix, LU workspace), and with the
//   default dynamic mmap threshold the kernel time to map and zero them
//   can match the time spent computing.
void tune_process_for_settling();

}  // namespace hj
