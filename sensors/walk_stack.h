#pragma once
// The stack of a BVH walk: kInPlace entries in place, doubling on the heap
// when a tree is deeper (an entry is never dropped). Bullet's builder keeps
// its trees within about log_1.5(triangles) levels (37 for its 2^21-triangle
// limit), so the heap is the exception. The heap's code is out of line
// (walk_stack.cc): the kernels built for wider instruction sets instantiate
// no library template (sandbox_isa_kernel in CMakeLists.txt).

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

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

// Heap memory for entries past the in-place ones.
class WalkHeap {
 public:
  WalkHeap() = default;
  ~WalkHeap();
  WalkHeap(const WalkHeap&) = delete;
  WalkHeap& operator=(const WalkHeap&) = delete;
  // `bytes` of memory holding the first `kept` bytes of `from`.
  void* Grow(const void* from, std::size_t kept, std::size_t bytes);

 private:
  void* data_{nullptr};
};

template <typename T, int kInPlace>
class WalkStack {
  static_assert(std::is_trivially_copyable_v<T>, "entries are moved as bytes");

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
    capacity_ *= 2;
    data_ = static_cast<T*>(
        heap_.Grow(data_, sizeof(T) * std::size_t(size_), sizeof(T) * std::size_t(capacity_)));
  }

  T in_place_[kInPlace];
  WalkHeap heap_;
  T* data_{in_place_};
  int size_{0}, capacity_{kInPlace};
};

}  // namespace sandbox::sensors
