#pragma once
// Orders shared pointers by the object's id, so containers iterate the same way on every run
// (pointer order would make deterministic mode depend on the allocator).
#include <memory>

namespace varslam::slam {

struct IdLess {
  template <typename T>
  bool operator()(const std::shared_ptr<T>& a, const std::shared_ptr<T>& b) const {
    return a->id() < b->id();
  }
};

}  // namespace varslam::slam
