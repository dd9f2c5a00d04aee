#include "memory.hpp"

#include <malloc.h>

namespace varia::host {

void keep_freed_memory() {
  mallopt(M_MMAP_THRESHOLD, 32 << 20);  // glibc's largest (DEFAULT_MMAP_THRESHOLD_MAX on 64-bit)
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
}

}  // namespace varia::host
