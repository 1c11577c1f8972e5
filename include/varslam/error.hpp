#pragma once
// Errors that reach the user. Every message names the file (and line, where there is one), or the key, and the
// problem. Part of the public API (C++17).
#include <stdexcept>
#include <string>

namespace varslam {

/// Bad input: a missing or malformed file, a broken setting, a frame of the wrong size or time. The message is
/// meant for the user as is.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A configuration key with a wrong name, type or value.
class ConfigError : public InputError {
 public:
  using InputError::InputError;
};

}  // namespace varslam
