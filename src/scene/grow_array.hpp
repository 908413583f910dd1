#pragma once
// An array of plain elements that grows without a serial pass over what it holds, for the OBJ reader's
// arrays of hundreds of millions of elements: elements added are left unset for the caller to write (on
// all cores, so the pages are first touched there), and past 1 MiB it lives in its own mapping, which
// grows by moving its pages (mremap) instead of copying them. Small arrays stay on the heap.
#include <sys/mman.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <new>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/parallel.hpp"

namespace rtr {

// A large array's pages made or dropped on all cores. The kernel's work on a page (clearing it at first
// touch, freeing it) costs about what the bake does with it, and it runs on one thread where a vector is
// resized (a serial memset) or an array freed: at 100 M triangles, seconds of the weld with 15 cores idle.
// Both only advise the kernel: without MADV_POPULATE_WRITE (Linux < 5.14) nothing is done ahead.
namespace pages {
constexpr size_t kPiece = size_t(8) << 20, kWorth = size_t(32) << 20;  // bytes
inline void advise(void* p, size_t bytes, int advice, unsigned threads) {
  if (bytes < kWorth || threads == 1) return;
  const uintptr_t page = 4096, lo = (reinterpret_cast<uintptr_t>(p) + page - 1) & ~(page - 1),
                  hi = (reinterpret_cast<uintptr_t>(p) + bytes) & ~(page - 1);
  parallelFor((hi - lo + kPiece - 1) / kPiece, threads, [&](size_t k) {
    const uintptr_t a = lo + k * kPiece;
    ::madvise(reinterpret_cast<void*>(a), std::min<uintptr_t>(kPiece, hi - a), advice);
  });
}
// The whole pages inside [p, p + bytes) given back now (their contents read as zeros after).
inline void drop(void* p, size_t bytes) {
  const uintptr_t page = 4096, lo = (reinterpret_cast<uintptr_t>(p) + page - 1) & ~(page - 1),
                  hi = (reinterpret_cast<uintptr_t>(p) + bytes) & ~(page - 1);
  if (hi > lo) ::madvise(reinterpret_cast<void*>(lo), hi - lo, MADV_DONTNEED);
}
}  // namespace pages

// Room for n elements in v, its new pages first touched on all cores (what v held is lost if it grows).
// A resize to n after it is then one thread's memset over pages already there.
template <class T>
void reserveOnAllCores(std::vector<T>& v, size_t n, unsigned threads) {
  if (n * sizeof(T) >= pages::kWorth && threads != 1 && n > v.capacity()) {
    std::vector<T>().swap(v);
    v.reserve(n);
    pages::advise(v.data(), n * sizeof(T), MADV_POPULATE_WRITE, threads);
  }
}

// v.resize(n) (value-initialised, as ever) with its new pages first touched on all cores.
template <class T>
void resizeOnAllCores(std::vector<T>& v, size_t n, unsigned threads) {
  reserveOnAllCores(v, n, threads);
  v.resize(n);
}

// Frees an array of n elements, its pages given back on all cores first (their contents are lost).
template <class T>
void freeOnAllCores(std::unique_ptr<T[]>& a, size_t n, unsigned threads) {
  if (a) pages::advise(a.get(), n * sizeof(T), MADV_DONTNEED, threads);
  a.reset();
}

template <class T>
class GrowArray {
  static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>);
  static constexpr size_t kMapBytes = size_t(1) << 20;

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
  ~GrowArray() {
    if (mapped(cap_)) ::munmap(data_, cap_ * sizeof(T));
    else std::free(data_);
  }

  // n elements; those added are unset. The capacity grows by half at least, so appends cost O(1) calls.
  void resize(size_t n) {
    if (n > cap_) grow(std::max(n, cap_ + cap_ / 2));
    size_ = n;
  }
  // The memory goes back now (its pages freed on `threads` threads).
  void release(unsigned threads = 1) {
    if (mapped(cap_)) pages::advise(data_, cap_ * sizeof(T), MADV_DONTNEED, threads);
    *this = GrowArray();
  }

  // Elements below n are read no more: past 1 MiB their whole pages go back now (they read as zeros after).
  void dropBelow(size_t n, unsigned threads = 1) {
    const size_t bytes = std::min(n, size_) * sizeof(T) & ~size_t(4095);  // the mapping starts on a page
    if (!mapped(cap_) || bytes == 0) return;
    if (bytes < pages::kWorth || threads == 1) ::madvise(data_, bytes, MADV_DONTNEED);
    else pages::advise(data_, bytes, MADV_DONTNEED, threads);
  }

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
  static bool mapped(size_t cap) { return cap * sizeof(T) >= kMapBytes; }

  void grow(size_t cap) {
    if (cap > std::numeric_limits<size_t>::max() / sizeof(T)) throw std::bad_alloc();
    const size_t bytes = cap * sizeof(T);
    void* p = nullptr;
    if (!mapped(cap)) {
      p = std::realloc(data_, bytes);
      if (!p) throw std::bad_alloc();
    } else if (mapped(cap_)) {
      p = ::mremap(data_, cap_ * sizeof(T), bytes, MREMAP_MAYMOVE);
      if (p == MAP_FAILED) throw std::bad_alloc();
    } else {  // from the heap into a mapping: the one copy, of less than kMapBytes
      p = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
      if (p == MAP_FAILED) throw std::bad_alloc();
      if (size_) std::memcpy(p, data_, size_ * sizeof(T));
      std::free(data_);
    }
    data_ = static_cast<T*>(p);
    cap_ = cap;
  }

  T* data_ = nullptr;
  size_t size_ = 0, cap_ = 0;
};

}  // namespace rtr
