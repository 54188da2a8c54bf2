#include "scenewatch/service/frame_budget.h"

#include <cassert>

namespace scenewatch::service {

bool FrameBudget::try_reserve(std::size_t bytes) {
  std::size_t now = reserved_.load();
  do {
    if (bytes > limit_bytes_ || now > limit_bytes_ - bytes) return false;
  } while (!reserved_.compare_exchange_weak(now, now + bytes));
  return true;
}

void FrameBudget::release(std::size_t bytes) {
  [[maybe_unused]] const std::size_t before = reserved_.fetch_sub(bytes);
  assert(before >= bytes);
}

}  // namespace scenewatch::service
