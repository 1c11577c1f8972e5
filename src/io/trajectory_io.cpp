#include "io/trajectory_io.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <array>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "io/text_lines.hpp"

namespace varslam {
namespace {
// Beyond this a coordinate is garbage (and squared in the ATE it would overflow), whatever the unit.
constexpr double kMaxCoordinate = 1e6;
// A repeated timestamp within these of the pose before it is the same measurement sent twice (real TUM ground
// truth has a few, 1 mm apart); farther, one of the two lines is wrong and an ATE against it would be too.
constexpr double kSameMeasurementM = 0.01;
constexpr double kSameMeasurementDeg = 1.0;

// Refuses a repeated timestamp whose pose is not the one before it, naming both lines.
void check_repeat_is_same_pose(const std::filesystem::path& file, const StampedPose& before, int before_line,
                               const StampedPose& again, int again_line) {
  const PoseGap gap = pose_gap(before, again);
  if (is_same_measurement(gap)) return;
  throw InputError(fmt::format("{}:{}: timestamp {:.6f} is also on line {} with another pose ({:.3f} m and {:.2f} deg "
                               "away); a timestamp may repeat only its pose: remove the wrong one of lines {} and {}",
                               file.string(), again_line, again.timestamp, before_line, gap.metres, gap.degrees,
                               before_line, again_line));
}
}  // namespace

PoseGap pose_gap(const StampedPose& a, const StampedPose& b) {
  return {(b.T_wc.translation() - a.T_wc.translation()).norm(),
          Eigen::AngleAxisd(a.T_wc.linear().transpose() * b.T_wc.linear()).angle() * 180.0 / std::numbers::pi};
}

bool is_same_measurement(const PoseGap& gap) {
  return gap.metres <= kSameMeasurementM && gap.degrees <= kSameMeasurementDeg;
}

Trajectory read_tum_trajectory(const std::filesystem::path& file) {
  Trajectory out;
  int prev_line = 0;
  int duplicates = 0;
  for_each_data_line(file, "trajectory file", [&](const TextLine& l) {
    const std::string& line = *l.text;
    const int line_no = l.number;
    std::array<double, 8> v{};
    bool ok = l.tokens.size() == v.size();
    for (std::size_t n = 0; ok && n < v.size(); ++n) ok = parse_double(l.tokens[n], v[n]);
    if (!ok)
      throw InputError(fmt::format("{}:{}: expected 'timestamp tx ty tz qx qy qz qw', got '{}'", file.string(),
                                   line_no, line));
    for (double x : v)
      if (!std::isfinite(x))
        throw InputError(fmt::format("{}:{}: non-finite value in '{}'", file.string(), line_no, line));
    for (int k = 1; k <= 3; ++k)
      if (std::abs(v[k]) > kMaxCoordinate)
        throw InputError(fmt::format("{}:{}: position {} m is not a camera position (more than {:g} m from the origin)",
                                     file.string(), line_no, v[k], kMaxCoordinate));
    if (!out.empty() && v[0] < out.back().timestamp)
      throw InputError(fmt::format("{}:{}: timestamp {:.6f} is before {:.6f} (line {}); timestamps must "
                                   "increase",
                                   file.string(), line_no, v[0], out.back().timestamp, prev_line));
    Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);  // Eigen's constructor takes w first
    const double norm = q.norm();
    if (norm < 1e-6)
      throw InputError(fmt::format("{}:{}: zero quaternion (qx qy qz qw = {} {} {} {})", file.string(), line_no,
                                   v[4], v[5], v[6], v[7]));
    q.coeffs() /= norm;  // files carry ~6 decimals: re-normalise rather than reject
    StampedPose p;
    p.timestamp = v[0];
    p.T_wc.linear() = q.toRotationMatrix();
    p.T_wc.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
    // Real TUM ground truth repeats a timestamp now and then, with the same pose to a millimetre; like the TUM
    // tools (a dict keyed by time), the later line wins.
    if (!out.empty() && v[0] == out.back().timestamp) {
      check_repeat_is_same_pose(file, out.back(), prev_line, p, line_no);
      out.back() = p;
      ++duplicates;
    } else {
      out.push_back(p);
    }
    prev_line = line_no;
  });
  if (duplicates > 0)
    spdlog::debug("{}: {} repeated timestamps with the same pose (within 1 cm and 1 deg), kept the later pose of each",
                  file.string(), duplicates);
  return out;
}

void write_tum_trajectory(const Trajectory& trajectory, const std::filesystem::path& file) {
  std::string text = "# timestamp tx ty tz qx qy qz qw (camera-to-world)\n";
  for (const auto& p : trajectory) {
    const Eigen::Quaterniond q = Eigen::Quaterniond(p.T_wc.linear()).normalized();
    const Eigen::Vector3d t = p.T_wc.translation();
    text += fmt::format("{:.6f} {:.9g} {:.9g} {:.9g} {:.9g} {:.9g} {:.9g} {:.9g}\n", p.timestamp, t.x(), t.y(), t.z(),
                        q.x(), q.y(), q.z(), q.w());
  }
  write_file_atomically(file, text, "trajectory file");
}

}  // namespace varslam
