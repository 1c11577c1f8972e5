#pragma once
// Matching two trajectories by timestamp, exactly like the TUM benchmark's associate.py (used by
// evaluate_ate): every pair (a, b) with |a - (b + offset)| < max_difference is a candidate; candidates are
// taken greedily by increasing difference (ties: earlier a, then earlier b), each pose at most once; the
// result is sorted by time. Poses sharing a timestamp count once (the last one in the file wins, as the
// Python dict does).
#include <cstddef>
#include <vector>

#include "core/trajectory.hpp"

namespace varslam {

struct TimestampMatch {
  std::size_t first = 0;   // index into the first trajectory (ground truth in evaluate_ate)
  std::size_t second = 0;  // index into the second trajectory (the estimate)
};

struct AssociationOptions {
  double offset = 0.0;           // added to the second trajectory's timestamps
  double max_difference = 0.02;  // seconds; strict: a pair at exactly this difference is rejected
};

/// One-to-one matches sorted by the first trajectory's timestamp. Inputs need not be sorted.
std::vector<TimestampMatch> associate_timestamps(const Trajectory& first, const Trajectory& second,
                                                 const AssociationOptions& options = {});

/// Index (into `sorted_stamps`, ascending) of the stamp nearest to t; ties go to the earlier stamp.
/// Precondition: sorted_stamps is not empty.
std::size_t nearest_timestamp_index(const std::vector<double>& sorted_stamps, double t);

}  // namespace varslam
