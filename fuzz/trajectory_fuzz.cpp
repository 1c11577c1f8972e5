// TUM trajectories (ground truth, estimates given to `varslam eval`): read or
// refused with InputError; what is read has finite, non-decreasing timestamps,
// bounded positions and rotations.
#include <cmath>

#include "core/error.hpp"
#include "fuzz_input.hpp"
#include "io/trajectory_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace varslam;
  const auto file = fuzz::write_input("trajectory.txt", data, size);
  Trajectory traj;
  try {
    traj = read_tum_trajectory(file);
  } catch (const InputError&) {
    return 0;
  }
  for (std::size_t i = 0; i < traj.size(); ++i) {
    const auto& p = traj[i];
    VARSLAM_FUZZ_EXPECT(std::isfinite(p.timestamp));
    if (i > 0) VARSLAM_FUZZ_EXPECT(p.timestamp > traj[i - 1].timestamp);
    VARSLAM_FUZZ_EXPECT(p.T_wc.translation().allFinite() && p.T_wc.translation().cwiseAbs().maxCoeff() <= 1e6);
    const Eigen::Matrix3d R = p.T_wc.linear();
    VARSLAM_FUZZ_EXPECT(R.allFinite());
    VARSLAM_FUZZ_EXPECT((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-9);
  }
  return 0;
}
