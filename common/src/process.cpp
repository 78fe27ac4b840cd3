#include "fsi/common/process.hpp"

#include <malloc.h>

namespace fsi {
void init_process() {
  mallopt(M_MMAP_THRESHOLD, 64 << 20);
  mallopt(M_TRIM_THRESHOLD, 128 << 20);
}
}  // namespace fsi
