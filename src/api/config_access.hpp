#pragma once
// The internal settings behind a varslam::Config (for the session and the tools; not installed).
#include <varslam/config.hpp>

#include "io/settings.hpp"

namespace varslam::detail {

struct ConfigAccess {
  /// A deep copy: later changes to the Config do not reach it.
  static Settings settings(const Config& c);
  static Config wrap(Settings s);
};

}  // namespace varslam::detail
