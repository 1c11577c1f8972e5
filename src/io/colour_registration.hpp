#pragma once
// Finds where a separate depth camera's pixels land in the colour image (raw Kinect v1, 7-Scenes), from the
// images alone: object outlines are jumps in depth and edges in colour, so the right mapping puts the depth
// jumps on strong colour gradients. The mapping searched is a zoom about the depth camera's principal point
// (colour focal = scale x depth focal), a shift, and the baseline between the two cameras along the image rows
// (a parallax that grows as 1 / depth; a shift alone fits it at one depth only). Registered data (TUM, Bonn,
// synthetic) comes out as identity.
#include <vector>

#include <opencv2/core.hpp>

#include "core/camera.hpp"

namespace varslam {

struct ColourRegistrationSearch {
  double min_scale = 0.85, max_scale = 1.05;  // colour focal / depth focal
  int max_shift_px = 12;                      // principal point shift searched, each axis
  double max_baseline_m = 0.06;               // depth camera x in the colour frame searched, +-; 0 = shift only
  double baseline_step_m = 0.005;             // coarse step of that search (refined to half of it)
  int points_per_frame = 2000;                // depth-edge pixels scored per frame (evenly subsampled)
  double min_gain = 1.25;       // best score / identity score needed before the mapping counts as found
  double min_change_px = 1.5;   // ... and it must move some image corner by at least this much
};

struct ColourRegistration {
  // colour pixel = scale * (depth pixel - c) + c + (du + colour fx * baseline_x / z, dv)
  double scale = 1.0, du = 0.0, dv = 0.0;
  double baseline_x = 0.0;      // the depth camera's origin in the colour frame along x (m)
  double score = 0.0;           // mean normalised colour gradient under the depth edges, at the best mapping
  double identity_score = 0.0;  // the same with colour pixel = depth pixel
  int frames = 0, edge_points = 0;
  bool found = false;  // the mapping clearly beats identity (see ColourRegistrationSearch)
  /// The colour camera implied by the mapping, given the depth camera (baseline and image size kept).
  PinholeCamera colour_camera(const PinholeCamera& depth) const;
};

/// Pixels on the near side of a depth jump (a 4-neighbour farther by more than rel_jump * z + abs_jump metres).
std::vector<cv::Point> occluding_edge_pixels(const cv::Mat& depth_m, double rel_jump = 0.05, double abs_jump = 0.03);

/// Estimates the mapping from pairs of gray (CV_8UC1) and depth (CV_32FC1, metres, depth camera geometry)
/// images of the same moments; a few frames of varied views suffice (10 in the tests, 20 in the runner).
ColourRegistration estimate_colour_registration(const std::vector<cv::Mat>& grays, const std::vector<cv::Mat>& depths_m,
                                                const PinholeCamera& depth_camera,
                                                const ColourRegistrationSearch& search = {});

}  // namespace varslam
