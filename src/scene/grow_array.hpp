#pragma once
// An array of plain elements that grows without a serial pass over what it holds, for the OBJ reader's
// arrays of hundreds of millions of elements: elements added are left unset for the caller to write (on
// all cores, so the pages are first touched there), and it grows by realloc, which for a large block
// (glibc maps those on their own) moves the pages (mremap) instead of copying them.
#include <algorithm>
#include <cstdlib>
#include <limits>
#include <new>
#include <span>
#include <type_traits>
#include <utility>

namespace rtr {

template <class T>
class GrowArray {
  static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>);

 public:
  GrowArray() = default;
  GrowArray(GrowArray&& o) noexcept
      : data_(std::exchange(o.data_, nullptr)), size_(std::exchange(o.size_, 0)), cap_(std::exchange(o.cap_, 0)) {}
  GrowArray& operator=(GrowArray&& o) noexcept {
    std::swap(data_, o.data_);
    std::swap(size_, o.size_);
    std::swap(cap_, o.cap_);
    return *this;
  }
  ~GrowArray() { std::free(data_); }

  // n elements; those added are unset. The capacity grows by half at least, so appends cost O(1) calls;
  // past 1 MiB it jumps to 64 MiB, beyond the size below which glibc may keep a block in its heap (and copy it).
  void resize(size_t n) {
    if (n > cap_) {
      size_t cap = std::max(n, cap_ + cap_ / 2);
      if (cap > std::numeric_limits<size_t>::max() / sizeof(T)) throw std::bad_alloc();
      if (cap * sizeof(T) > (size_t(1) << 20)) cap = std::max(cap, (size_t(64) << 20) / sizeof(T));
      void* p = std::realloc(data_, cap * sizeof(T));
      if (!p) throw std::bad_alloc();
      data_ = static_cast<T*>(p);
      cap_ = cap;
    }
    size_ = n;
  }
  void release() { *this = GrowArray(); }  // the memory goes back now

  size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  T* data() { return data_; }
  const T* data() const { return data_; }
  T* begin() { return data_; }
  T* end() { return data_ + size_; }
  T& operator[](size_t i) { return data_[i]; }
  const T& operator[](size_t i) const { return data_[i]; }
  operator std::span<const T>() const { return {data_, size_}; }

 private:
  T* data_ = nullptr;
  size_t size_ = 0, cap_ = 0;
};

}  // namespace rtr
