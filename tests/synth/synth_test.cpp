// Generator tests: output layout and parsing, determinism, sensor statistics, boxes, poses, config errors, and the
// static world being the same for every scenario (only the movers differ).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "core/error.hpp"
#include "io/boxes_io.hpp"
#include "io/settings.hpp"
#include "io/trajectory_io.hpp"
#include "synth/camera_path.hpp"
#include "synth/movers.hpp"
#include "synth/renderer.hpp"
#include "synth/sensor.hpp"
#include "synth/synth.hpp"
#include "file_text.hpp"

namespace fs = std::filesystem;
using namespace varslam;
using namespace varslam::synth;

namespace {

fs::path temp_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("varslam_synth_test_" + name);
  fs::remove_all(d);
  return d;
}

SynthConfig short_config(const std::string& scenario, double seconds = 1.0, double fps = 10.0) {
  SynthConfig cfg;
  cfg.scenario = scenario;
  cfg.seconds = seconds;
  cfg.fps = fps;
  return cfg;
}

std::vector<std::pair<double, std::string>> read_list(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::pair<double, std::string>> out;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ss(line);
    double t;
    std::string name;
    ss >> t >> name;
    out.emplace_back(t, name);
  }
  return out;
}

using test::slurp;

}  // namespace

TEST(Synth, ScenarioNamesAreTheDocumentedOnes) {
  EXPECT_EQ(scenario_names(),
            (std::vector<std::string>{"static", "walking", "unknown_box", "obstructing_box", "balloon", "mixed", "large_box",
                                      "large_box_people"}));
}

TEST(Synth, EveryScenarioWritesAParsableTumFolder) {
  for (const auto& name : scenario_names()) {
    SCOPED_TRACE(name);
    const fs::path dir = temp_dir("layout_" + name);
    const SynthSummary s = generate(short_config(name), dir);
    ASSERT_EQ(s.frames, 10u);
    for (const char* f : {"rgb.txt", "depth.txt", "groundtruth.txt", "boxes.txt", "settings.yaml", "scenario.json",
                          "preview.png"})
      EXPECT_TRUE(fs::exists(dir / f)) << f;
    const auto rgb = read_list(dir / "rgb.txt"), depth = read_list(dir / "depth.txt");
    ASSERT_EQ(rgb.size(), 10u);
    ASSERT_EQ(depth.size(), 10u);
    for (std::size_t i = 0; i < rgb.size(); ++i) {
      EXPECT_NEAR(rgb[i].first - rgb[0].first, i / 10.0, 1e-6);
      EXPECT_EQ(rgb[i].first, depth[i].first);
    }
    const cv::Mat c = cv::imread((dir / rgb[3].second).string(), cv::IMREAD_UNCHANGED);
    const cv::Mat d = cv::imread((dir / depth[3].second).string(), cv::IMREAD_UNCHANGED);
    ASSERT_EQ(c.type(), CV_8UC3);
    ASSERT_EQ(d.type(), CV_16UC1);
    EXPECT_EQ(c.size(), cv::Size(640, 480));
    EXPECT_EQ(d.size(), cv::Size(640, 480));
    EXPECT_GT(cv::countNonZero(d), 640 * 480 / 2);  // most pixels have depth
    cv::Scalar mean, stddev;
    cv::meanStdDev(c, mean, stddev);
    EXPECT_GT(stddev[0], 10.0);  // a textured room, not a flat image

    const Trajectory gt = read_tum_trajectory(dir / "groundtruth.txt");
    ASSERT_EQ(gt.size(), 10u);
    EXPECT_NEAR(gt[0].timestamp, rgb[0].first, 1e-6);
    EXPECT_LT(gt[0].T_wc.translation().norm(), 1e-6);  // path re-expressed relative to its first pose
    EXPECT_NO_THROW(read_boxes_file(dir / "boxes.txt"));
    const Settings st = load_settings(dir / "settings.yaml");
    EXPECT_DOUBLE_EQ(st.camera.fx, 525.0);
    EXPECT_DOUBLE_EQ(st.camera.cy, 239.5);
    EXPECT_DOUBLE_EQ(st.depth_factor, 5000.0);
    EXPECT_NEAR(st.camera.bf, 40.0, 1e-9);
    const auto j = nlohmann::json::parse(slurp(dir / "scenario.json"));
    EXPECT_EQ(j.at("scenario"), name);
    EXPECT_EQ(j.at("frames"), 10);
    fs::remove_all(dir);
  }
}

TEST(Synth, SameSeedGivesIdenticalBytesOtherSeedDiffers) {
  auto cfg = short_config("mixed", 0.3);
  cfg.seed = 7;
  const fs::path a = temp_dir("det_a"), b = temp_dir("det_b"), c = temp_dir("det_c");
  generate(cfg, a);
  generate(cfg, b);
  cfg.seed = 8;
  generate(cfg, c);
  std::size_t compared = 0;
  for (const auto& e : fs::recursive_directory_iterator(a)) {
    if (!e.is_regular_file()) continue;
    const fs::path rel = fs::relative(e.path(), a);
    EXPECT_EQ(slurp(e.path()), slurp(b / rel)) << rel;
    ++compared;
  }
  EXPECT_EQ(compared, 3u * 2u + 7u);
  const auto list = read_list(a / "rgb.txt");
  EXPECT_NE(slurp(a / list[1].second), slurp(c / list[1].second));
  for (const auto& d : {a, b, c}) fs::remove_all(d);
}

TEST(SynthSensor, DepthNoiseMatchesTheKinectModel) {
  SplitMix64 rng(3);
  const GaussianTable gauss(5);
  DepthSensorParams p;
  p.edge_holes = false;
  p.random_holes = 0;
  for (const double z : {1.0, 2.0, 4.0}) {
    const cv::Mat1f plane(480, 640, static_cast<float>(z));
    const cv::Mat1w raw = sense_depth(plane, p, rng, gauss);
    cv::Mat1d metres;
    raw.convertTo(metres, CV_64F, 1.0 / 5000.0);
    cv::Scalar mean, sd;
    cv::meanStdDev(metres, mean, sd);
    const double sigma = 0.0012 + 0.0019 * (z - 0.4) * (z - 0.4);
    EXPECT_DOUBLE_EQ(kinect_depth_sigma(z), sigma);
    EXPECT_NEAR(mean[0], z, 3 * sigma / std::sqrt(640.0 * 480.0) + 1e-4) << z;
    // Quantisation (0.2 mm steps) adds 0.2^2/12 mm^2 of variance: negligible at these sigmas.
    EXPECT_NEAR(sd[0], sigma, 0.03 * sigma) << z;
  }
}

TEST(SynthSensor, DepthDropsBeyondRangeAndAtDiscontinuities) {
  SplitMix64 rng(3);
  const GaussianTable gauss(5);
  DepthSensorParams p;
  p.random_holes = 0;
  cv::Mat1f step(100, 100, 1.5f);
  step.colRange(50, 100).setTo(3.0f);
  step.rowRange(0, 10).setTo(6.0f);  // beyond the 5.5 m range
  const cv::Mat1w raw = sense_depth(step, p, rng, gauss);
  EXPECT_EQ(cv::countNonZero(raw.rowRange(0, 10)), 0);
  // The far side of the edge (column 50) is lost in most rows, pixels away from the edge are kept.
  EXPECT_LT(cv::countNonZero(raw(cv::Rect(50, 12, 1, 88))), 30);
  EXPECT_EQ(cv::countNonZero(raw(cv::Rect(10, 12, 30, 88))), 30 * 88);
  p.edge_holes = false;
  p.noise = false;
  const cv::Mat1w clean = sense_depth(step, p, rng, gauss);
  EXPECT_EQ(clean(50, 20), 7500);  // 1.5 m at factor 5000, exact without noise
  EXPECT_EQ(clean(50, 70), 15000);
}

TEST(Synth, PeopleBoxesAreInsideTheImageAndPresentWhenPeopleAreVisible) {
  const fs::path dir = temp_dir("boxes");
  const SynthSummary s = generate(short_config("walking", 2.0, 5.0), dir);
  EXPECT_GE(s.people, 2u);
  EXPECT_GT(s.frames_with_person, 0u);
  const BoxesByTime boxes = read_boxes_file(dir / "boxes.txt");
  EXPECT_EQ(boxes.size(), s.frames_with_person);  // no misses configured: a box whenever someone is in view
  std::size_t n = 0;
  for (const auto& [t, dets] : boxes)
    for (const auto& d : dets) {
      EXPECT_EQ(d.label, "person");
      EXPECT_GE(d.box.x, 0.0f);
      EXPECT_GE(d.box.y, 0.0f);
      EXPECT_GT(d.box.width, 0.0f);
      EXPECT_GT(d.box.height, 0.0f);
      EXPECT_LE(d.box.x + d.box.width, 640.0f);
      EXPECT_LE(d.box.y + d.box.height, 480.0f);
      ++n;
    }
  EXPECT_EQ(n, s.person_boxes);

  // The box must cover the person: pixels inside are mostly nearer than the room behind.
  const auto depth_list = read_list(dir / "depth.txt");
  const auto& [t0, dets0] = *boxes.begin();
  std::string depth_file;
  for (const auto& [t, f] : depth_list)
    if (std::abs(t - t0) < 1e-6) depth_file = f;
  ASSERT_FALSE(depth_file.empty());
  const cv::Mat1w depth = cv::imread((dir / depth_file).string(), cv::IMREAD_UNCHANGED);
  EXPECT_GT(cv::countNonZero(depth(cv::Rect(dets0[0].box))), 0);

  // Misses drop boxes, jitter moves them but keeps them in the image.
  auto cfg = short_config("walking", 2.0, 5.0);
  cfg.box_miss_rate = 1.0;
  generate(cfg, dir);
  EXPECT_TRUE(read_boxes_file(dir / "boxes.txt").empty());
  cfg.box_miss_rate = 0.0;
  cfg.box_jitter_px = 4.0;
  generate(cfg, dir);
  const BoxesByTime jittered = read_boxes_file(dir / "boxes.txt");
  ASSERT_EQ(jittered.size(), boxes.size());
  double moved = 0;
  std::size_t matched = 0;
  for (const auto& [t, dets] : jittered) {
    const auto& ref = boxes.at(t);
    ASSERT_LE(dets.size(), ref.size());
    for (const auto& d : dets) {
      EXPECT_GE(d.box.x, 0.0f);
      EXPECT_LE(d.box.x + d.box.width, 640.0f);
    }
    // Every box clearly wider than the jitter survives it, near its unjittered place. (A sliver at the image
    // border may be jittered out of the image.)
    for (const auto& r : ref) {
      if (r.box.width < 30 || r.box.height < 30) continue;
      double best = 1e9;
      for (const auto& d : dets) best = std::min(best, static_cast<double>(std::abs(d.box.x - r.box.x)));
      EXPECT_LT(best, 20.0) << "box at t=" << t << " lost by the jitter";
      moved += best;
      ++matched;
    }
  }
  ASSERT_GT(matched, 0u);
  EXPECT_GT(moved / static_cast<double>(matched), 1.0);
  fs::remove_all(dir);
}

TEST(Synth, StaticSceneHasNoBoxes) {
  const fs::path dir = temp_dir("static");
  const SynthSummary s = generate(short_config("static", 0.5), dir);
  EXPECT_EQ(s.person_boxes, 0u);
  EXPECT_EQ(s.people, 0u);
  EXPECT_EQ(s.unknown_movers, 0u);
  EXPECT_TRUE(read_boxes_file(dir / "boxes.txt").empty());
  fs::remove_all(dir);
}

TEST(Synth, GroundTruthEqualsTheInterpolatedPathRelativeToItsStart) {
  const fs::path path_dir = fs::path(VARSLAM_SHARED_DIR) / "trajectories" / "rgbd_dataset_freiburg1_desk";
  if (!fs::exists(path_dir / "groundtruth.txt")) GTEST_SKIP() << "no shared trajectories";
  auto cfg = short_config("static", 0.5, 30.0);
  cfg.path_file = path_dir;  // a folder holding groundtruth.txt
  cfg.path_start = 3.0;
  cfg.preview = false;
  const fs::path dir = temp_dir("gt");
  generate(cfg, dir);
  const Trajectory path = read_tum_trajectory(path_dir / "groundtruth.txt");
  const Trajectory gt = read_tum_trajectory(dir / "groundtruth.txt");
  ASSERT_EQ(gt.size(), 15u);
  const double t0 = path.front().timestamp + 3.0;
  EXPECT_NEAR(gt[0].timestamp, t0, 1e-6);
  const Eigen::Isometry3d T0_inv = interpolate_pose(path, t0).inverse();
  for (const auto& p : gt) {
    const Eigen::Isometry3d expect = T0_inv * interpolate_pose(path, p.timestamp);
    EXPECT_LT((p.T_wc.translation() - expect.translation()).norm(), 1e-5);
    EXPECT_LT(Eigen::AngleAxisd(p.T_wc.rotation().transpose() * expect.rotation()).angle(), 1e-5);
  }
  fs::remove_all(dir);
}

TEST(SynthPath, InterpolationIsLerpPlusSlerp) {
  Trajectory path(2);
  path[0].timestamp = 10.0;
  path[1].timestamp = 11.0;
  path[1].T_wc.translation() = Eigen::Vector3d(1, 2, 3);
  path[1].T_wc.linear() = Eigen::AngleAxisd(0.8, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Isometry3d m = interpolate_pose(path, 10.25);
  EXPECT_LT((m.translation() - Eigen::Vector3d(0.25, 0.5, 0.75)).norm(), 1e-12);
  const Eigen::AngleAxisd aa(m.rotation());
  EXPECT_NEAR(aa.angle(), 0.2, 1e-9);
  EXPECT_NEAR(std::abs(aa.axis().y()), 1.0, 1e-9);
  EXPECT_TRUE(interpolate_pose(path, 12.0).isApprox(path[1].T_wc));  // clamped at the ends
}

TEST(SynthPath, BuiltInPathIsARealTwentySecondExcerpt) {
  const Trajectory p = builtin_camera_path();
  ASSERT_GT(p.size(), 550u);
  EXPECT_GT(p.back().timestamp - p.front().timestamp, 20.0);
  double travelled = 0;
  for (std::size_t i = 1; i < p.size(); ++i) {
    EXPECT_GT(p[i].timestamp, p[i - 1].timestamp);
    travelled += (p[i].T_wc.translation() - p[i - 1].T_wc.translation()).norm();
  }
  EXPECT_GT(travelled, 1.0);  // hand-held motion, not a still camera
}

TEST(Synth, BadConfigurationThrowsInputError) {
  const fs::path dir = temp_dir("bad");
  auto expect_error = [&](SynthConfig cfg, const std::string& fragment) {
    try {
      generate(cfg, dir);
      ADD_FAILURE() << "no error for " << fragment;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  expect_error(short_config("dancing"), "unknown scenario 'dancing'");
  expect_error(short_config("walking", 25.0, 30.0), "20.57 s long");  // built-in path is shorter
  expect_error(short_config("walking", 1.0, 0.0), "fps");
  expect_error(short_config("walking", 1.0, std::nan("")), "fps");
  expect_error(short_config("walking", -1.0), "seconds");
  auto miss = short_config("walking");
  miss.box_miss_rate = 1.5;
  expect_error(miss, "miss rate");
  auto late = short_config("walking", 5.0);
  late.path_start = 18.0;
  expect_error(late, "starting at 18.00 s");
  auto nofile = short_config("walking");
  nofile.path_file = dir / "missing.txt";
  expect_error(nofile, "missing.txt");
  fs::remove_all(dir);
}

TEST(SynthMovers, ObstructingBoxFillsALargePartOfTheImage) {
  const auto still = [](double) { return Eigen::Isometry3d(Eigen::Isometry3d::Identity()); };
  ViewAnchor anchor;
  const Movers movers = Movers::script("obstructing_box", anchor, 1.35, 10.0, still, 3);
  ASSERT_EQ(movers.objects().size(), 1u);
  const auto& ep = movers.objects()[0].episodes.at(0);
  Scene scene = build_static_scene({-4, -1.4, -2}, {4, 1.35, 6}, anchor, {}, 1);
  Movers m = movers;
  m.add_materials(scene);
  const Renderer renderer{PinholeCamera{}};
  RenderOutput out;
  double max_share = 0;
  for (double u : {0.4, 0.5, 0.6}) {
    std::vector<Primitive> dyn;
    m.primitives_at(ep.start + u * ep.length, dyn);
    renderer.render(scene, dyn, Eigen::Isometry3d::Identity(), out);
    const double share = cv::countNonZero(out.ids >= kFirstObjectId) / (640.0 * 480.0);
    EXPECT_GT(share, 0.3) << u;
    EXPECT_LT(share, 0.75) << u;
    max_share = std::max(max_share, share);
  }
  // Out of view before the episode.
  std::vector<Primitive> dyn;
  m.primitives_at(ep.start + 0.01, dyn);
  renderer.render(scene, dyn, Eigen::Isometry3d::Identity(), out);
  EXPECT_EQ(cv::countNonZero(out.ids >= kFirstObjectId), 0);
}

TEST(SynthMovers, PeopleAreHumanSizedAndWalkAtHumanSpeed) {
  const auto still = [](double) { return Eigen::Isometry3d(Eigen::Isometry3d::Identity()); };
  const Movers m = Movers::script("walking", ViewAnchor{}, 1.35, 10.0, still, 9);
  ASSERT_GE(m.people().size(), 2u);
  for (const auto& p : m.people()) {
    EXPECT_GE(p.height, 1.6);
    EXPECT_LE(p.height, 1.9);
    std::vector<Primitive> parts;
    person_primitives(p, 0.7, 1.35, parts);
    double top = 1e9;
    for (const auto& q : parts) {
      Eigen::Vector3d lo, hi;
      q.bounds(lo, hi);
      top = std::min(top, lo.y());
      EXPECT_EQ(q.object_id, p.id);
    }
    EXPECT_NEAR(1.35 - top, p.height, 0.06);  // head top at the person's height above the floor
    std::vector<double> speeds;
    for (int k = 0; k < 21; ++k) {
      Eigen::Vector2d a, b, h;
      double phase;
      p.state_at(0.5 * k, a, h, phase);
      p.state_at(0.5 * k + 0.1, b, h, phase);
      speeds.push_back((b - a).norm() / 0.1);
    }
    std::nth_element(speeds.begin(), speeds.begin() + 10, speeds.end());  // median: turns are rare
    EXPECT_GE(speeds[10], 0.8);
    EXPECT_LE(speeds[10], 1.5 + 1e-9);
  }
}

namespace {

// Byte comparison of every frame (colour and depth) of two generated folders; returns the number of frames that differ.
std::size_t differing_frames(const fs::path& a, const fs::path& b) {
  const auto list_a = read_list(a / "rgb.txt"), list_b = read_list(b / "rgb.txt");
  const auto depth_a = read_list(a / "depth.txt"), depth_b = read_list(b / "depth.txt");
  EXPECT_EQ(list_a.size(), list_b.size());
  EXPECT_FALSE(list_a.empty());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < std::min(list_a.size(), list_b.size()); ++i) {
    EXPECT_EQ(list_a[i], list_b[i]);
    const bool same = slurp(a / list_a[i].second) == slurp(b / list_b[i].second) &&
                      slurp(a / depth_a[i].second) == slurp(b / depth_b[i].second);
    if (!same) ++differ;
  }
  return differ;
}

SynthConfig world_config(const std::string& scenario) {
  auto cfg = short_config(scenario, 0.4, 10.0);
  cfg.seed = 5;
  cfg.preview = false;
  return cfg;
}

}  // namespace

TEST(SynthWorld, EveryScenarioWithHiddenMoversRendersExactlyTheStaticSequence) {
  const fs::path ref = temp_dir("world_static"), dir = temp_dir("world_hidden");
  generate(world_config("static"), ref);
  const auto static_json = nlohmann::json::parse(slurp(ref / "scenario.json"));
  for (const auto& name : scenario_names()) {
    SCOPED_TRACE(name);
    auto cfg = world_config(name);
    cfg.render_movers = false;
    generate(cfg, dir);
    EXPECT_EQ(differing_frames(ref, dir), 0u);
    const auto j = nlohmann::json::parse(slurp(dir / "scenario.json"));
    EXPECT_EQ(j.at("room"), static_json.at("room"));
    EXPECT_EQ(j.at("static_primitives"), static_json.at("static_primitives"));
    EXPECT_EQ(j.at("render_movers"), false);
    EXPECT_TRUE(read_boxes_file(dir / "boxes.txt").empty());
  }
  fs::remove_all(ref);
  fs::remove_all(dir);
}

TEST(SynthWorld, VisibleMoversAreTheOnlyDifferenceFromStatic) {
  // Same seed, same path: walking differs from static only around the people (their pixels, the depth holes at
  // their outline, the motion blur spreading their colour); the sensor noise elsewhere is the same.
  const fs::path ref = temp_dir("world_static2"), dir = temp_dir("world_walking");
  auto cfg = world_config("static");
  cfg.seconds = 2.0;
  cfg.fps = 5.0;
  generate(cfg, ref);
  cfg.scenario = "walking";
  const SynthSummary s = generate(cfg, dir);
  ASSERT_GT(s.frames_with_person, 0u);
  EXPECT_GE(differing_frames(ref, dir), s.frames_with_person);  // movers are rendered
  const BoxesByTime boxes = read_boxes_file(dir / "boxes.txt");
  const auto colour = read_list(dir / "rgb.txt"), depth = read_list(dir / "depth.txt");
  std::size_t changed_inside = 0;
  for (std::size_t i = 0; i < colour.size(); ++i) {
    cv::Mat1b outside(480, 640, uchar{255});
    for (const auto& [t, dets] : boxes)
      if (std::abs(t - colour[i].first) < 1e-6)
        for (const auto& d : dets) {
          const cv::Rect grown = cv::Rect(d.box) + cv::Size(32, 32) - cv::Point(16, 16);  // blur reach
          outside(grown & cv::Rect(0, 0, 640, 480)).setTo(0);
        }
    for (const auto& name : {colour[i].second, depth[i].second}) {
      const cv::Mat a = cv::imread((ref / name).string(), cv::IMREAD_UNCHANGED);
      const cv::Mat b = cv::imread((dir / name).string(), cv::IMREAD_UNCHANGED);
      cv::Mat diff;
      cv::absdiff(a, b, diff);
      std::vector<cv::Mat> channels;
      cv::split(diff, channels);
      cv::Mat any = channels[0];
      for (std::size_t c = 1; c < channels.size(); ++c) any = any | channels[c];
      const cv::Mat1b per_pixel = any != 0;
      changed_inside += static_cast<std::size_t>(cv::countNonZero(per_pixel & ~outside));
      EXPECT_EQ(cv::countNonZero(per_pixel & outside), 0) << name;
    }
  }
  EXPECT_GT(changed_inside, 1000u);
  fs::remove_all(ref);
  fs::remove_all(dir);
}

TEST(SynthMovers, EachScenarioSelectsItsMoversFromOneSharedPlan) {
  const auto still = [](double) { return Eigen::Isometry3d(Eigen::Isometry3d::Identity()); };
  const Movers plan = Movers::plan_all(ViewAnchor{}, 1.35, 10.0, still, 4);
  ASSERT_EQ(plan.people().size(), 3u);
  ASSERT_EQ(plan.objects().size(), 4u);  // carried box, balloon, obstructing box, large box
  EXPECT_TRUE(plan.select("static").people().empty());
  EXPECT_TRUE(plan.select("static").objects().empty());
  EXPECT_TRUE(plan.select("static").keep_outs().empty());
  const Movers walking = plan.select("walking"), mixed = plan.select("mixed");
  EXPECT_GE(walking.people().size(), 2u);
  EXPECT_TRUE(walking.objects().empty());
  ASSERT_EQ(mixed.people().size(), 2u);
  ASSERT_EQ(mixed.objects().size(), 2u);
  // The same person walks the same lane in every scenario that shows them.
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(mixed.people()[i].waypoints, walking.people()[i].waypoints);
    EXPECT_EQ(mixed.people()[i].height, walking.people()[i].height);
    EXPECT_EQ(mixed.people()[i].look_seed, walking.people()[i].look_seed);
  }
  EXPECT_EQ(mixed.objects()[0].kind, ObjectScript::Kind::CarriedBox);
  EXPECT_EQ(mixed.objects()[1].kind, ObjectScript::Kind::Balloon);
  EXPECT_EQ(mixed.objects()[1].id, kFirstObjectId + 1);
  const Movers balloon = plan.select("balloon");
  ASSERT_EQ(balloon.objects().size(), 1u);
  EXPECT_EQ(balloon.objects()[0].id, kFirstObjectId);  // ids renumbered per scenario
  EXPECT_EQ(balloon.objects()[0].waypoints, mixed.objects()[1].waypoints);
  EXPECT_EQ(plan.select("obstructing_box").objects().at(0).kind, ObjectScript::Kind::ObstructingBox);
  // The plan's keep-outs cover every scenario's lanes.
  EXPECT_GE(plan.keep_outs().size(), walking.keep_outs().size() + plan.select("unknown_box").keep_outs().size());
  // Another seed moves the movers.
  EXPECT_NE(Movers::plan_all(ViewAnchor{}, 1.35, 10.0, still, 5).people()[0].waypoints, plan.people()[0].waypoints);
}
