#include "sim/process_tuning.h"

#include <mutex>

#ifdef __GLIBC__
#include <malloc.h>
#endif

extern "C" void openblas_set_num_threads(int) __attribute__((weak));

namespace hj {

void tune_process_for_settling() {
  static std::once_flag once;
  std::call_once(once, [] {
    if (openblas_set_num_threads) openblas_set_num_threads(1);
#ifdef __GLIBC__
    // Blocks up to 64 MiB come from the heap and are reused; up to 128 MiB
    // of free heap is kept rather than trimmed. Fixing the threshold also
    // turns off glibc's own adaptive one.
    mallopt(M_MMAP_THRESHOLD, 64 << 20);
    mallopt(M_TRIM_THRESHOLD, 128 << 20);
#endif
  });
}

}  // namespace hj
