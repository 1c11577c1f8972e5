#include "io/trajectory_io.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "core/error.hpp"

namespace varslam {
namespace {

// strtod accepts "nan"/"inf", so they reach the finiteness check with a precise message instead of
// being reported as a malformed line.
bool parse_double(const std::string& token, double& out) {
  char* end = nullptr;
  out = std::strtod(token.c_str(), &end);
  return end != token.c_str() && *end == '\0';
}

}  // namespace

Trajectory read_tum_trajectory(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(fmt::format("{}: cannot open trajectory file", file.string()));
  Trajectory out;
  std::string line;
  int line_no = 0;
  int prev_line = 0;
  int duplicates = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream ss(line);
    std::array<double, 8> v{};
    std::string token;
    std::size_t n = 0;
    bool ok = true;
    while (ss >> token) {
      if (n == v.size() || !parse_double(token, v[n])) {
        ok = false;
        break;
      }
      ++n;
    }
    if (!ok || n != v.size())
      throw InputError(fmt::format("{}:{}: expected 'timestamp tx ty tz qx qy qz qw', got '{}'", file.string(),
                                   line_no, line));
    for (double x : v)
      if (!std::isfinite(x))
        throw InputError(fmt::format("{}:{}: non-finite value in '{}'", file.string(), line_no, line));
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
    // Real TUM ground truth repeats a timestamp now and then; like the TUM tools (a dict keyed by time),
    // the later line wins.
    if (!out.empty() && v[0] == out.back().timestamp) {
      out.back() = p;
      ++duplicates;
    } else {
      out.push_back(p);
    }
    prev_line = line_no;
  }
  if (duplicates > 0)
    spdlog::debug("{}: {} repeated timestamps, kept the later pose of each", file.string(), duplicates);
  return out;
}

void write_tum_trajectory(const Trajectory& trajectory, const std::filesystem::path& file) {
  std::ofstream out(file);
  if (!out) throw InputError(fmt::format("{}: cannot write trajectory file", file.string()));
  out << "# timestamp tx ty tz qx qy qz qw (camera-to-world)\n";
  for (const auto& p : trajectory) {
    const Eigen::Quaterniond q = Eigen::Quaterniond(p.T_wc.linear()).normalized();
    const Eigen::Vector3d t = p.T_wc.translation();
    out << fmt::format("{:.6f} {:.9g} {:.9g} {:.9g} {:.9g} {:.9g} {:.9g} {:.9g}\n", p.timestamp, t.x(), t.y(),
                       t.z(), q.x(), q.y(), q.z(), q.w());
  }
  if (!out) throw InputError(fmt::format("{}: error while writing trajectory file", file.string()));
}

}  // namespace varslam
