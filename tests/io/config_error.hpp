#pragma once
// Runs fn, expects a ConfigError and returns its message (a test failure, and "", when none is thrown).
#include <gtest/gtest.h>

#include <string>

#include "core/error.hpp"

namespace varslam::testing {

template <typename Fn>
std::string config_error(Fn&& fn) {
  try {
    fn();
  } catch (const ConfigError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected a ConfigError";
  return {};
}

}  // namespace varslam::testing
