#pragma once
// The `semantic:` section of a settings file -> detector and filter configuration.
//
//   semantic:
//     detector: yolo            # yolo | boxes | hog | none
//     model: yolo-fastest-1.1-xl  # preset, or model_cfg/model_weights (Darknet) / model_weights: x.onnx
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
};

/// Defaults for missing keys; a key with a wrong type or value is a ConfigError naming the settings file and key.
SemanticSettings semantic_settings(const Settings& s);

}  // namespace varslam::semantic
