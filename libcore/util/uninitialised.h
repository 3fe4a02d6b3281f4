// An allocator for arrays of trivial values that are written whole right after they are sized: where
// std::allocator's resize writes a zero into every new element first, this one leaves it unset, so a
// coupe's hundreds of MB of points are written once, by what computes or reads them.
#pragma once

#include <memory>
#include <type_traits>
#include <utility>

namespace hairgen {

// An allocator's construct: a new element with no value given is default-initialised, which for a
// trivial type writes nothing (UninitialisedAllocator, MappableAllocator).
struct LeavesNewElementsUnset {
  template <class U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

template <class T>
struct UninitialisedAllocator : std::allocator<T>, LeavesNewElementsUnset {
  static_assert(std::is_trivially_default_constructible_v<T>);
  template <class U>
  struct rebind {
    using other = UninitialisedAllocator<U>;
  };
  UninitialisedAllocator() = default;
  template <class U>
  UninitialisedAllocator(const UninitialisedAllocator<U>&) noexcept {}
};

}  // namespace hairgen
