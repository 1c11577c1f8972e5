#include "io/trajectory_io.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "core/error.hpp"
#include "io/temp_dir.hpp"

namespace varslam {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using varslam::testing::TempDir;

std::string input_error(const std::filesystem::path& file) {
  try {
    read_tum_trajectory(file);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an InputError for " << file;
  return {};
}

TEST(TrajectoryIo, RoundTripKeepsPosesAndTimestamps) {
  TempDir dir;
  Trajectory traj;
  for (int i = 0; i < 20; ++i) {
    StampedPose p;
    p.timestamp = 1305031102.175304 + i * 0.033333;
    const Eigen::Vector3d axis = Eigen::Vector3d(0.3, -0.5, 0.8 + i * 0.1).normalized();
    p.T_wc.linear() = Eigen::AngleAxisd(0.1 * i - 0.7, axis).toRotationMatrix();
    p.T_wc.translation() = Eigen::Vector3d(0.01 * i, -1.25 + 0.002 * i, 2.5);
    traj.push_back(p);
  }
  const auto file = dir / "traj.txt";
  write_tum_trajectory(traj, file);
  const Trajectory back = read_tum_trajectory(file);
  ASSERT_EQ(back.size(), traj.size());
  for (std::size_t i = 0; i < traj.size(); ++i) {
    EXPECT_NEAR(back[i].timestamp, traj[i].timestamp, 1e-6);
    EXPECT_TRUE(back[i].T_wc.translation().isApprox(traj[i].T_wc.translation(), 1e-8));
    EXPECT_TRUE(back[i].T_wc.linear().isApprox(traj[i].T_wc.linear(), 1e-8));
  }
}

TEST(TrajectoryIo, ReadsTumLinesWithCommentsAndRenormalisesQuaternions) {
  TempDir dir;
  const auto file = dir.write("gt.txt",
                              "# ground truth\n"
                              "# timestamp tx ty tz qx qy qz qw\n"
                              "\n"
                              "1.0 1 2 3 0 0 0 1\n"
                              "  2.5\t-1 -2 -3 0 0 0.7072 0.7072\n");  // |q| = 1.0001: re-normalised
  const Trajectory t = read_tum_trajectory(file);
  ASSERT_EQ(t.size(), 2u);
  EXPECT_DOUBLE_EQ(t[0].timestamp, 1.0);
  EXPECT_TRUE(t[0].T_wc.translation().isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_TRUE(t[0].T_wc.linear().isIdentity(1e-12));
  EXPECT_DOUBLE_EQ(t[1].timestamp, 2.5);
  // 90 degrees about z: x axis maps to y.
  EXPECT_TRUE((t[1].T_wc.linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-9));
  EXPECT_NEAR(t[1].T_wc.linear().determinant(), 1.0, 1e-12);
}

TEST(TrajectoryIo, ErrorsNameFileAndLine) {
  TempDir dir;
  const std::string ok = "# header\n1.0 0 0 0 0 0 0 1\n";
  struct Case {
    std::string bad_line, expect;
  };
  for (const Case& c : {Case{"2.0 0 0 0 0 0 1", "expected"}, Case{"2.0 0 0 0 0 0 0 1 9", "expected"},
                        Case{"2.0 0 x 0 0 0 0 1", "expected"}, Case{"2.0 nan 0 0 0 0 0 1", "non-finite"},
                        Case{"inf 0 0 0 0 0 0 1", "non-finite"}, Case{"2.0 0 0 0 0 0 0 0", "zero quaternion"},
                        Case{"0.5 0 0 0 0 0 0 1", "is before"}}) {
    const auto file = dir.write("t.txt", ok + c.bad_line + "\n");
    EXPECT_THAT(input_error(file), AllOf(HasSubstr(file.string() + ":3:"), HasSubstr(c.expect))) << c.bad_line;
  }
  EXPECT_THAT(input_error(dir / "missing.txt"), HasSubstr("missing.txt"));
}

TEST(TrajectoryIo, RepeatedTimestampWithTheSamePoseKeepsTheLaterPoseLikeTheTumTools) {
  TempDir dir;
  // As in TUM fr2/desk_with_person: the same stamp twice, 1 mm and a tenth of a degree apart.
  const auto file = dir.write("gt.txt", "1.0 0 0 0 0 0 0 1\n2.0 1 0 0 0 0 0 1\n2.0 1.001 0 0 0 0 0.001 1\n"
                                        "3.0 2 0 0 0 0 0 1\n");
  const Trajectory t = read_tum_trajectory(file);
  ASSERT_EQ(t.size(), 3u);
  EXPECT_DOUBLE_EQ(t[1].timestamp, 2.0);
  EXPECT_DOUBLE_EQ(t[1].T_wc.translation().x(), 1.001);
  EXPECT_DOUBLE_EQ(t[2].timestamp, 3.0);
}

TEST(TrajectoryIo, RepeatedTimestampWithAnotherPoseIsAnErrorNamingBothLines) {
  TempDir dir;
  const auto moved = dir.write("moved.txt", "# gt\n1.0 0 0 0 0 0 0 1\n2.0 1 0 0 0 0 0 1\n2.0 1.5 0 0 0 0 0 1\n");
  EXPECT_THAT(input_error(moved), AllOf(HasSubstr(moved.string() + ":4: timestamp 2.000000 is also on line 3"),
                                        HasSubstr("0.500 m"), HasSubstr("lines 3 and 4")));
  const auto turned = dir.write("turned.txt", "1.0 0 0 0 0 0 0 1\n1.0 0 0 0 0 0 0.1 1\n");
  EXPECT_THAT(input_error(turned), AllOf(HasSubstr(turned.string() + ":2:"), HasSubstr("11.42 deg")));
}

TEST(TrajectoryIo, WriteToUnwritablePathThrows) {
  TempDir dir;
  EXPECT_THROW(write_tum_trajectory({StampedPose{}}, dir / "no_such_dir" / "t.txt"), InputError);
}

TEST(TrajectoryIo, ReadsEverySharedReferenceTrajectory) {
  const std::filesystem::path root = std::filesystem::path(VARSLAM_SHARED_DIR) / "trajectories";
  if (!std::filesystem::exists(root)) GTEST_SKIP() << "shared data not present";
  int files = 0;
  for (const auto& seq : std::filesystem::directory_iterator(root)) {
    if (!seq.is_directory()) continue;
    for (const char* name : {"groundtruth.txt", "reference_estimate_CameraTrajectory.txt"}) {
      const auto f = seq.path() / name;
      if (!std::filesystem::exists(f)) continue;
      EXPECT_GT(read_tum_trajectory(f).size(), 100u) << f;
      ++files;
    }
  }
  EXPECT_GE(files, 2);
}

}  // namespace
}  // namespace varslam
