#pragma once
// The `semantic:` section of a settings file -> detector and filter configuration.
//
//   semantic:
//     detector: yolo            # yolo | boxes | hog | none
//     model: yolo-fastest-1.1_body  # preset, or model_cfg/model_weights (Darknet) / model_weights: x.onnx
//     model_dir: ../models      # relative paths are relative to the settings file
//     names_file: coco.names
//     input_size: 320
//     conf_threshold: 0.3
//     nms_threshold: 0.45
//     classes: [person]
//     label_aliases: {body: person}
//     num_threads: 0
//     boxes_file: boxes.txt
//     box_enlarge: 0.1
//     depth_band_m: 0.5
//     silhouette_margin_px: 0   # e.g. 5: drop background keypoints this close to the person's pixels (0 = off)
//     min_exclusive_share: 1    # e.g. 0.2: overlapping boxes also get a person depth from their own part (1 = off)
//     asynchronous: true        # false: wait for each frame's detections (deterministic)
//     propagate_boxes: true     # shift stale boxes by optical flow
//     deterministic_detect_every: 0  # deterministic mode: detect on every n-th frame (0: 1 for a boxes file, else 2)
//     deterministic_detect_lag: -1   # ... and take the result this many frames later (-1: every - 1)
//     mask_extraction: true     # extract no keypoints on the people: the budget goes to the background
#include "io/settings.hpp"
#include "semantic/detector.hpp"
#include "semantic/keypoint_filter.hpp"

namespace varslam::semantic {

struct SemanticSettings {
  DetectorConfig detector;
  FilterConfig filter;
  bool asynchronous = setting_keys::bool_default("semantic.asynchronous");
  bool propagate_boxes = setting_keys::bool_default("semantic.propagate_boxes");
  bool mask_extraction = setting_keys::bool_default("semantic.mask_extraction");
  // Deterministic mode only (real-time mode gives the detector every frame and uses its freshest result).
  int deterministic_detect_every = setting_keys::int_default("semantic.deterministic_detect_every");
  int deterministic_detect_lag = setting_keys::int_default("semantic.deterministic_detect_lag");
};

/// The deterministic schedule with its automatic values resolved: a boxes file costs nothing, so it is read on every
/// frame; a detector that computes runs on every 2nd frame, beside the tracking of the frame after.
int resolved_detect_every(const SemanticSettings& s);
int resolved_detect_lag(const SemanticSettings& s);

/// Defaults for missing keys; a key with a wrong type or value is a ConfigError naming the settings file and key.
SemanticSettings semantic_settings(const Settings& s);

}  // namespace varslam::semantic
