#pragma once
// Everything tracking and mapping need from the optimisers.
#include "optim/kernel.hpp"
#include "optim/local_ba.hpp"
#include "optim/pose_optimizer.hpp"
#include "optim/reprojection.hpp"
