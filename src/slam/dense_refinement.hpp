#pragma once
// The drift that sparse points leave between keyframes seen seconds apart, removed with their depth: every pair of
// keyframes at least min_gap_s apart whose views overlap is aligned by dense ICP (slam/dense_alignment.hpp); the
// alignments that pass the gates become edges of an SE(3) pose graph with the keyframes' own chain of relative
// poses, and the graph gives the keyframes' corrected poses.
#include <vector>

#include <Eigen/Geometry>

#include "core/camera.hpp"
#include "slam/keyframe.hpp"

namespace varslam::slam {

struct DenseRefinementConfig {
  double min_gap_s = 5.0;            // pairs closer in time are tied by shared points already
  double max_angle_deg = 35.0;       // optical axes at most this far apart ...
  double max_distance_m = 1.5;       // ... and centres this close: views that may overlap
  double min_overlap = 0.35;         // share of the source's points matched for an alignment to count
  double max_correction_m = 0.08;    // an alignment that moves the pair more than this is a wrong fit, not drift
  double max_correction_deg = 3.0;
  double edge_weight = 0.09;         // a dense edge against a chain edge (each alignment is one view of noisy depth)
  std::size_t max_pairs = 2000;      // at most this many alignments, spread evenly over the candidates
};

struct DenseRefinementResult {
  std::size_t candidates = 0, aligned = 0, edges = 0;
  double mean_correction_m = 0;  // how far the edges moved their pairs from the poses before
};

/// `keyframes` in creation order with their poses `T_cw` (same size); on return `T_cw` holds the corrected poses
/// (unchanged when no edge passes). Keyframes without a depth sample take part in the chain only. The first
/// keyframe of each map segment holds that segment's gauge.
DenseRefinementResult refine_poses_with_depth(const std::vector<KeyFramePtr>& keyframes, const PinholeCamera& camera,
                                              std::vector<Eigen::Isometry3d>& T_cw,
                                              const DenseRefinementConfig& cfg = {});

}  // namespace varslam::slam
