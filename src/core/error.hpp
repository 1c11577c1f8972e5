#pragma once
// The errors that reach the user are part of the public API: <varslam/error.hpp>.
#include <varslam/error.hpp>
