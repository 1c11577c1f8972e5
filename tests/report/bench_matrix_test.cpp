#include "report/bench_matrix.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include "core/error.hpp"
#include "io/trajectory_io.hpp"
#include "report/bench_runner.hpp"
#include "synth/synth.hpp"

namespace varslam::report {
namespace {
namespace fs = std::filesystem;

bool contains(const std::vector<std::string>& v, const std::string& s) { return std::find(v.begin(), v.end(), s) != v.end(); }

TEST(Configurations, TheFourAblationsInPaperOrder) {
  std::vector<std::string> names;
  for (const auto& c : known_configurations()) names.push_back(c.name);
  EXPECT_EQ(names, (std::vector<std::string>{"huber", "semantic", "kernel", "full"}));
  EXPECT_THROW(configuration_by_name("fastest"), InputError);
}

TEST(Configurations, OverridesMatchTheAblation) {
  const auto huber = configuration_overrides(configuration_by_name("huber"), "boxes", "/s/boxes.txt");
  EXPECT_TRUE(contains(huber, "tracking.kernel=huber"));
  EXPECT_TRUE(contains(huber, "mapping.kernel=huber"));
  EXPECT_TRUE(contains(huber, "semantic.detector=none"));

  const auto semantic = configuration_overrides(configuration_by_name("semantic"), "boxes", "/s/boxes.txt");
  EXPECT_TRUE(contains(semantic, "tracking.kernel=huber"));
  EXPECT_TRUE(contains(semantic, "semantic.detector=boxes"));
  EXPECT_TRUE(contains(semantic, "semantic.boxes_file=/s/boxes.txt"));

  const auto kernel = configuration_overrides(configuration_by_name("kernel"), "boxes", "/s/boxes.txt");
  EXPECT_TRUE(contains(kernel, "tracking.kernel=barron-fixed"));
  for (const auto& o : kernel)  // tracking's alpha is the default (-2), not pinned to the paper's 1
    EXPECT_EQ(o.rfind("tracking.barron_alpha", 0), std::string::npos) << o;
  EXPECT_TRUE(contains(kernel, "mapping.kernel=barron-adaptive"));
  EXPECT_TRUE(contains(kernel, "semantic.detector=none"));

  const auto full_yolo = configuration_overrides(configuration_by_name("full"), "yolo", {});
  EXPECT_TRUE(contains(full_yolo, "mapping.kernel=barron-adaptive"));
  EXPECT_TRUE(contains(full_yolo, "semantic.detector=yolo"));
  EXPECT_THROW(configuration_overrides(configuration_by_name("full"), "boxes", {}), InputError);
  EXPECT_THROW(configuration_overrides(configuration_by_name("full"), "hog?", {}), InputError);
}

TEST(NamedMatrices, DefaultIsTheQuickCheckAndLargeMoversTheLongOne) {
  const NamedMatrix& quick = matrix_by_name("default");
  const BenchOptions defaults;
  EXPECT_EQ(quick.scenarios, defaults.scenarios);
  EXPECT_EQ(quick.seeds, defaults.seeds);
  EXPECT_DOUBLE_EQ(quick.seconds, 3.0);
  const NamedMatrix& large = matrix_by_name("large_movers");
  EXPECT_EQ(large.scenarios, (std::vector<std::string>{"large_box", "large_box_people"}));
  EXPECT_EQ(large.seeds.size(), 5u);
  EXPECT_GE(large.paths.size(), 3u);
  EXPECT_DOUBLE_EQ(large.seconds, 20.0);
  // Every scenario it names is one the generator knows.
  const auto known = synth::scenario_names();
  for (const auto& s : large.scenarios) EXPECT_NE(std::find(known.begin(), known.end(), s), known.end()) << s;
  try {
    matrix_by_name("large-movers");
    FAIL() << "an unknown matrix must be refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("known: default, large_movers"), std::string::npos) << e.what();
  }
}

TEST(CameraPath, ShortNames) {
  EXPECT_EQ(short_path_name("rgbd_dataset_freiburg2_desk_with_person"), "fr2_desk_with_person");
  EXPECT_EQ(short_path_name("rgbd_bonn_crowd3"), "bonn_crowd3");
  EXPECT_EQ(short_path_name("my_path"), "my_path");
}

class CameraPathTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / "varslam_bench_matrix_test" / "rgbd_dataset_freiburg9_test";
    fs::create_directories(dir_);
    Trajectory t;
    for (int i = 0; i <= 200; ++i) {  // 20 s at 10 Hz
      StampedPose p;
      p.timestamp = 1000.0 + 0.1 * i;
      t.push_back(p);
    }
    write_tum_trajectory(t, dir_ / "groundtruth.txt");
  }
  void TearDown() override { fs::remove_all(dir_.parent_path()); }
  fs::path dir_;
};

TEST_F(CameraPathTest, CentredWindowByDefaultAndExplicitStart) {
  const auto c = resolve_camera_path("rgbd_dataset_freiburg9_test", dir_.parent_path(), 6.0);
  EXPECT_EQ(c.name, "fr9_test");
  EXPECT_EQ(c.file, dir_ / "groundtruth.txt");
  EXPECT_NEAR(c.duration, 20.0, 1e-9);
  EXPECT_NEAR(c.start, 7.0, 1e-9);  // (20 - 6) / 2
  const auto at = resolve_camera_path((dir_ / "groundtruth.txt").string() + "@2.5", {}, 6.0);
  EXPECT_NEAR(at.start, 2.5, 1e-9);
}

TEST_F(CameraPathTest, RejectsTooShortOrMissingPaths) {
  EXPECT_THROW(resolve_camera_path("rgbd_dataset_freiburg9_test", dir_.parent_path(), 19.8), InputError);
  EXPECT_THROW(resolve_camera_path("rgbd_dataset_freiburg9_test@15", dir_.parent_path(), 6.0), InputError);
  EXPECT_THROW(resolve_camera_path("rgbd_dataset_freiburg9_test@abc", dir_.parent_path(), 6.0), InputError);
  EXPECT_THROW(resolve_camera_path("no_such_path", dir_.parent_path(), 6.0), InputError);
}

TEST(Sequences, MatrixOrderIdsAndCacheKeys) {
  CameraPathChoice a{"pa", "/p/a.txt", 30, 10}, b{"pb", "/p/b.txt", 30, 12};
  const auto seqs = synthetic_sequences({"static", "walking"}, {a, b}, {1, 2}, 5.0, "/cache");
  ASSERT_EQ(seqs.size(), 8u);
  EXPECT_EQ(seqs[0].scenario, "static");
  EXPECT_EQ(seqs[0].path_name, "pa");
  EXPECT_EQ(seqs[1].seed, 2u);
  EXPECT_EQ(seqs[2].path_name, "pb");
  EXPECT_EQ(seqs[4].scenario, "walking");
  EXPECT_EQ(seqs[0].dir, fs::path("/cache") / seqs[0].id);
  std::vector<std::string> ids;
  for (const auto& s : seqs) ids.push_back(s.id);
  std::sort(ids.begin(), ids.end());
  EXPECT_EQ(std::unique(ids.begin(), ids.end()), ids.end()) << "ids must be unique";
  EXPECT_NE(synth_cache_key(seqs[0]), synth_cache_key(seqs[1]));  // seed differs
  EXPECT_NE(synth_cache_key(seqs[0]), synth_cache_key(seqs[2]));  // path differs
  const auto args = synth_arguments(seqs[3]);
  EXPECT_EQ(args.front(), "synth");
  EXPECT_TRUE(contains(args, "--path-start"));
  EXPECT_TRUE(contains(args, "12"));
  EXPECT_TRUE(contains(args, "/p/b.txt"));
  EXPECT_FALSE(contains(args, "--sensor"));
  EXPECT_EQ(synth_cache_key(seqs[0]).find("sensor"), std::string::npos);  // caches made before sensors had names
}

TEST(Sequences, ARealSensorMatrixHasItsOwnSequences) {
  CameraPathChoice a{"pa", "/p/a.txt", 30, 10};
  const auto plain = synthetic_sequences({"static"}, {a}, {1}, 5.0, "/cache");
  const auto kinect = synthetic_sequences({"static"}, {a}, {1}, 5.0, "/cache", "kinect1");
  ASSERT_EQ(kinect.size(), 1u);
  EXPECT_NE(kinect[0].id, plain[0].id);
  EXPECT_NE(kinect[0].dir, plain[0].dir);
  EXPECT_NE(synth_cache_key(kinect[0]), synth_cache_key(plain[0]));
  const auto args = synth_arguments(kinect[0]);
  const auto at = std::find(args.begin(), args.end(), "--sensor");
  ASSERT_NE(at, args.end());
  EXPECT_EQ(*(at + 1), "kinect1");
}

TEST(Sequences, RealFolder) {
  const auto dir = fs::temp_directory_path() / "varslam_real_seq_test";
  fs::create_directories(dir);
  const auto s = real_sequence(dir.string() + "/");
  EXPECT_TRUE(s.real);
  EXPECT_EQ(s.id, "real__varslam_real_seq_test");
  EXPECT_EQ(s.path_name, "varslam_real_seq_test");
  fs::remove_all(dir);
  EXPECT_THROW(real_sequence(dir), InputError);
}

TEST(SplitList, TrimsAndDropsEmpty) {
  EXPECT_EQ(split_list(" a, b,,c ,"), (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_TRUE(split_list("").empty());
}

}  // namespace
}  // namespace varslam::report
