// Allocator settings and the process's resident size (memory.h).
#include "scenewatch/core/memory.h"

#include <atomic>
#include <fstream>
#include <mutex>
#include <string>
// After a C++ library header, which defines __GLIBC__ on glibc.
#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace scenewatch {

void keep_frame_buffers_in_heap() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_THRESHOLD, 512 << 20);
  mallopt(M_TRIM_THRESHOLD, 1024 << 20);
#endif
}

void give_back_free_memory() {
#if defined(__GLIBC__)
  // A trim walks every arena under its lock (milliseconds for a heap of a GiB): one at a time,
  // and a request made while one runs is served by running it again, never lost.
  static std::atomic<bool> requested{false};
  static std::mutex running;
  requested = true;
  for (;;) {
    std::unique_lock<std::mutex> lock(running, std::try_to_lock);
    if (!lock.owns_lock()) return;  // the thread trimming now will see `requested`
    while (requested.exchange(false)) malloc_trim(0);
    lock.unlock();
    if (!requested.load()) return;
  }
#endif
}

double resident_mib(int pid) {
  std::ifstream status(pid == 0 ? std::string("/proc/self/status") : "/proc/" + std::to_string(pid) + "/status");
  std::string key;
  while (status >> key) {
    if (key == "VmRSS:") {
      double kib = 0;
      status >> kib;
      return kib / 1024.0;
    }
    std::getline(status, key);
  }
  return 0.0;
}

}  // namespace scenewatch
