#pragma once
// The stack of a BVH walk: kInPlace entries in place, doubling on the heap
// when a tree is deeper (an entry is never dropped). Bullet's builder keeps
// its trees within about log_1.5(triangles) levels (37 for its 2^21-triangle
// limit), so the heap is the exception.

#include <cstdint>
#include <vector>

namespace sandbox::sensors {

// A packet walk's stack entry: a hierarchy reference and the lanes that
// entered its box, in one word, written and read whole (an entry stored in
// two parts and loaded as one stalls the load until both stores retire).
class WalkEntry {
 public:
  WalkEntry() = default;
  WalkEntry(std::int32_t ref, std::uint32_t lanes)
      : bits_(std::uint32_t(ref) | std::uint64_t(lanes) << 32) {}
  std::int32_t ref() const { return std::int32_t(std::uint32_t(bits_)); }
  std::uint32_t lanes() const { return std::uint32_t(bits_ >> 32); }

 private:
  std::uint64_t bits_{0};
};

template <typename T, int kInPlace>
class WalkStack {
 public:
  WalkStack() = default;
  WalkStack(const WalkStack&) = delete;
  WalkStack& operator=(const WalkStack&) = delete;

  void Push(const T& entry) {
    if (size_ == capacity_) Grow();
    data_[size_++] = entry;
  }
  T Pop() { return data_[--size_]; }
  bool empty() const { return size_ == 0; }
  int size() const { return size_; }
  bool on_heap() const { return data_ != in_place_; }

 private:
  void Grow() {
    if (heap_.empty()) heap_.assign(in_place_, in_place_ + size_);
    capacity_ *= 2;
    heap_.resize(static_cast<std::size_t>(capacity_));
    data_ = heap_.data();
  }

  T in_place_[kInPlace];
  std::vector<T> heap_;
  T* data_{in_place_};
  int size_{0}, capacity_{kInPlace};
};

}  // namespace sandbox::sensors
