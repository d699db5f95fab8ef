#include "sensors/walk_stack.h"

#include <cstdlib>
#include <new>

namespace sandbox::sensors {

WalkHeap::~WalkHeap() { std::free(data_); }

void* WalkHeap::Grow(const void* from, std::size_t kept, std::size_t bytes) {
  void* grown = std::malloc(bytes);
  if (grown == nullptr) throw std::bad_alloc();
  std::memcpy(grown, from, kept);
  std::free(data_);
  data_ = grown;
  return grown;
}

}  // namespace sandbox::sensors
