// Memory a program has freed, handed back to the system. The allocator keeps freed blocks
// for reuse and returns to the system only what lies at the top of its heap; a run's set-up
// and each cycle end free large arrays in the middle of it (the steady start, the balance's
// tree), whose pages stay resident while the time loop's own arrays, allocated after, do not
// fill them: 15 MB on the full tree (bench/README.md). glibc's malloc_trim(0) releases every
// free page; elsewhere this does nothing.
#pragma once

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace hemotree {

inline void return_free_memory() {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
}

}  // namespace hemotree
