// SPDX-License-Identifier: Apache-2.0
// Objects kept by their type, at most one of each: what a caller keeps between calls on behalf of
// code it does not know (a method's state between frames in MethodCache, a method's buffers with a
// GpuScene), so that neither has to name the types it keeps.
#pragma once

#include <map>
#include <memory>
#include <typeindex>
#include <typeinfo>
#include <utility>

namespace ao {

class TypedSlots {
 public:
  /// The T kept here, made by `make()` (which returns a std::unique_ptr<T> or std::shared_ptr<T>)
  /// when there is none, and made again when `fresh(const T&)` says the kept one no longer serves.
  template <class T, class Make, class Fresh>
  T& get(Make&& make, Fresh&& fresh) {
    std::shared_ptr<void>& slot = slots_[std::type_index(typeid(T))];
    if (!slot || !fresh(*static_cast<const T*>(slot.get()))) slot = std::shared_ptr<T>(make());
    return *static_cast<T*>(slot.get());
  }
  /// The same, kept for as long as this object lives.
  template <class T, class Make>
  T& get(Make&& make) {
    return get<T>(std::forward<Make>(make), [](const T&) { return true; });
  }
  /// The T kept here, or null.
  template <class T>
  T* find() const {
    const auto it = slots_.find(std::type_index(typeid(T)));
    return it == slots_.end() ? nullptr : static_cast<T*>(it->second.get());
  }

 private:
  std::map<std::type_index, std::shared_ptr<void>> slots_;
};

}  // namespace ao
