#pragma once
// An array that is either an owned std::vector or a read-only view of memory that a shared owner keeps
// alive (a mapped file: the scene's geometry read from .rtrscene, docs/startup.md "Scene file read").
// Readers see std::vector's const interface; a view is never copied behind their back. Writers build a
// vector and move it in, or call writable(), which copies a view into an owned vector once (explicit: a
// loaded scene's arrays stay views until code that changes them asks). The growing calls below
// (push_back, insert, resize, reserve) are writes too and go through writable(); clear() and assign()
// replace the contents without copying.
#include <algorithm>
#include <cstddef>
#include <initializer_list>
#include <memory>
#include <span>
#include <utility>
#include <vector>

namespace rtr {

template <class T>
class ViewOrVector {
 public:
  using value_type = T;
  using size_type = size_t;
  using const_iterator = const T*;
  using iterator = const T*;  // reads only: element writes go through writable()

  ViewOrVector() = default;
  ViewOrVector(std::vector<T> v) : vec_(std::move(v)) {}  // NOLINT: a vector moves in implicitly
  ViewOrVector(std::initializer_list<T> v) : vec_(v) {}
  // `items` must stay valid while `owner` lives; the array holds the owner.
  static ViewOrVector view(std::span<const T> items, std::shared_ptr<const void> owner) {
    ViewOrVector a;
    a.view_ = items;
    a.owner_ = std::move(owner);
    return a;
  }

  bool isView() const { return owner_ != nullptr; }
  const std::shared_ptr<const void>& owner() const { return owner_; }

  std::span<const T> span() const { return owner_ ? view_ : std::span<const T>(vec_); }
  operator std::span<const T>() const { return span(); }  // NOLINT: reads take spans
  const T* data() const { return owner_ ? view_.data() : vec_.data(); }
  size_t size() const { return owner_ ? view_.size() : vec_.size(); }
  bool empty() const { return size() == 0; }
  const T& operator[](size_t i) const { return data()[i]; }
  const T* begin() const { return data(); }
  const T* end() const { return data() + size(); }
  const T& front() const { return data()[0]; }
  const T& back() const { return data()[size() - 1]; }

  // The owned vector to change, a view copied into it first (once; the owner is let go).
  std::vector<T>& writable() {
    if (owner_) {
      vec_.assign(view_.begin(), view_.end());
      view_ = {};
      owner_.reset();
    }
    return vec_;
  }

  void clear() { forget().clear(); }
  void assign(size_t n, const T& v) { forget().assign(n, v); }
  template <class It>
  void assign(It first, It last) {
    const auto keep = owner_;  // [first, last) may lie in this view: its mapping lives until copied
    forget().assign(first, last);
  }
  void push_back(T v) { writable().push_back(v); }  // by value: `v` may be an element of the view
  template <class... A>
  T& emplace_back(A&&... a) {
    const auto keep = owner_;  // the arguments may refer to this view's elements
    return writable().emplace_back(std::forward<A>(a)...);
  }
  template <class It>
  void insert(const T* at, It first, It last) {  // `at`: end() or a position in this array
    const auto k = at - data();
    const auto keep = owner_;  // [first, last) may lie in this view
    std::vector<T>& v = writable();
    v.insert(v.begin() + k, first, last);
  }
  void insert(const T* at, std::initializer_list<T> items) { insert(at, items.begin(), items.end()); }
  void resize(size_t n) { writable().resize(n); }
  void resize(size_t n, const T& v) { writable().resize(n, v); }
  void reserve(size_t n) { writable().reserve(n); }

  friend bool operator==(const ViewOrVector& a, const ViewOrVector& b) {
    return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin());
  }

 private:
  std::vector<T>& forget() {
    view_ = {};
    owner_.reset();
    return vec_;
  }

  std::vector<T> vec_;
  std::span<const T> view_;
  std::shared_ptr<const void> owner_;
};

}  // namespace rtr
