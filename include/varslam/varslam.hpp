#pragma once
// varslam's public API in one include: the pipeline (varslam::Slam), its events, and the settings it reads.
#include "io/settings.hpp"           // load_settings, default_settings
#include "io/settings_registry.hpp"  // apply_setting_overrides, setting<T>
#include "pipeline/events.hpp"       // Observer and the events it receives
#include "pipeline/slam.hpp"         // varslam::Slam
