#pragma once
// Everything the tracker needs from the semantic module.
#include "semantic/async_detector.hpp"
#include "semantic/box_propagation.hpp"
#include "semantic/detector.hpp"
#include "semantic/detector_settings.hpp"
#include "semantic/dynamic_keypoint_masker.hpp"
#include "semantic/filter_stages_image.hpp"
#include "semantic/keypoint_filter.hpp"
