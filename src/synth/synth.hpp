#pragma once
// Synthetic dynamic-scene generator: renders a textured room, furniture, walking people and unknown movers
// along a real recorded camera path, with Kinect-like sensor effects, into a TUM RGB-D style folder.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "synth/real_sensor.hpp"

namespace varslam::synth {

/// Changes whenever the same configuration renders different files (written to scenario.json; the bench cache
/// key in report/bench_matrix.cpp repeats it). 2: the static room is the same for every scenario; 3: shelves
/// and cabinets along the walls where the movers leave the middle free.
inline constexpr int kGeneratorVersion = 3;

struct SynthConfig {
  std::string scenario = "walking";  // static | walking | unknown_box | obstructing_box | balloon | mixed |
                                     // large_box | large_box_people (20-s large-movers sequences)
  double seconds = 10.0;
  double fps = 30.0;
  std::uint64_t seed = 1;
  std::filesystem::path path_file;  // TUM groundtruth file (or a folder holding groundtruth.txt); empty = built-in
  double path_start = 0.0;          // seconds into the path where the sequence starts
  bool preview = true;              // write preview.png (contact sheet)
  double box_miss_rate = 0.0, box_jitter_px = 0.0;  // detector-like imperfection of the written person boxes
  // Debug switch: lay the scenario out as usual but leave its movers out of the images. The static world depends
  // only on (path, seed), so any scenario rendered this way equals `static` byte for byte.
  bool render_movers = true;

  // Sensor realism (all on by default; set to 0 / false to switch one off).
  bool depth_noise = true;          // sigma(z) = 0.0012 + 0.0019 (z - 0.4)^2 metres
  bool depth_edge_holes = true;     // missing depth at depth discontinuities
  double depth_max_m = 5.5;         // no depth beyond this range (0 = unlimited)
  int random_holes_per_frame = 4;   // small blobs of missing depth
  double image_noise_sigma = 2.0;   // grey levels, Gaussian
  bool motion_blur = true;          // blur along the image motion caused by the camera during the exposure
  double exposure_s = 0.012;        // exposure time used for motion blur
  double exposure_drift = 0.06;     // amplitude of the slow gain drift (0.06 = +-6 %)
  RealSensorEffects real;           // what a real camera adds beyond the above (all off; kinect1_sensor(): measured)
  int png_compression = 1;

  /// Called after each finished frame (from a worker thread, serialised): frames done, total.
  std::function<void(std::size_t, std::size_t)> progress;
};

struct SynthSummary {
  std::size_t frames = 0;
  double seconds_taken = 0.0;  // wall time of generate()
  std::filesystem::path dir;
  std::size_t people = 0;          // number of walking people in the scene
  std::size_t unknown_movers = 0;  // movers without a label (boxes, balloon)
  std::size_t person_boxes = 0;    // lines written to boxes.txt
  std::size_t frames_with_person = 0;  // frames where at least one person is visible
};

/// Names accepted by SynthConfig::scenario.
std::vector<std::string> scenario_names();

/// Render the sequence into out_dir (created if missing). Throws InputError on a bad configuration or path.
SynthSummary generate(const SynthConfig& cfg, const std::filesystem::path& out_dir);

}  // namespace varslam::synth
