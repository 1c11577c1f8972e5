#pragma once
// Errors that reach the user. Every message names the file (and line, where there is one) and the problem.
#include <stdexcept>
#include <string>

namespace varslam {

/// Bad input: a missing or malformed file, a broken setting. The message is meant for the user as is.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A configuration key with a wrong type or value.
class ConfigError : public InputError {
 public:
  using InputError::InputError;
};

}  // namespace varslam
