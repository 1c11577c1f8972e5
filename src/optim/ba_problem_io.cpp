#include "optim/ba_problem_io.hpp"

#include <array>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace varslam::optim {
namespace {

constexpr std::array<char, 8> kMagic = {'V', 'S', 'L', 'B', 'A', 'P', 'R', 'B'};
constexpr std::uint32_t kVersion = 1;
// Bytes of one record in the file, to check a count against what the file still holds before allocating.
constexpr std::uint64_t kKeyframeBytes = 7 * 8 + 1;
constexpr std::uint64_t kPointBytes = 3 * 8;
constexpr std::uint64_t kObservationBytes = 2 * 4 + 5 * 8;

class Writer {
 public:
  explicit Writer(const std::filesystem::path& path) : path_(path), out_(path, std::ios::binary) {
    if (!out_) throw std::runtime_error(path.string() + ": cannot be written");
  }
  template <typename T>
  void put(T v) {
    static_assert(std::is_arithmetic_v<T>);
    out_.write(reinterpret_cast<const char*>(&v), sizeof v);
  }
  void bytes(const char* p, std::size_t n) { out_.write(p, static_cast<std::streamsize>(n)); }
  void finish() {
    out_.flush();
    if (!out_) throw std::runtime_error(path_.string() + ": writing failed (disk full?)");
  }

 private:
  std::filesystem::path path_;
  std::ofstream out_;
};

class Reader {
 public:
  explicit Reader(const std::filesystem::path& path) : path_(path), in_(path, std::ios::binary) {
    if (!in_) throw std::runtime_error(path.string() + ": cannot be opened");
    in_.seekg(0, std::ios::end);
    size_ = static_cast<std::uint64_t>(in_.tellg());
    in_.seekg(0);
  }
  template <typename T>
  T get(const char* what) {
    static_assert(std::is_arithmetic_v<T>);
    T v{};
    in_.read(reinterpret_cast<char*>(&v), sizeof v);
    if (!in_) fail(std::string("the file ends inside ") + what + " (truncated)");
    return v;
  }
  void bytes(char* p, std::size_t n, const char* what) {
    in_.read(p, static_cast<std::streamsize>(n));
    if (!in_) fail(std::string("the file ends inside ") + what + " (truncated)");
  }
  /// A record count, checked against the bytes left (a damaged count must not allocate gigabytes).
  std::uint64_t count(const char* what, std::uint64_t record_bytes) {
    const auto n = get<std::uint64_t>(what);
    const std::uint64_t left = size_ - static_cast<std::uint64_t>(in_.tellg());
    if (n > left / record_bytes)
      fail(std::string(what) + " count " + std::to_string(n) + " needs more bytes than the file has left (" +
           std::to_string(left) + "): truncated or damaged");
    return n;
  }
  bool at_end() { return in_.peek() == std::char_traits<char>::eof(); }
  [[noreturn]] void fail(const std::string& problem) const {
    throw std::runtime_error(path_.string() + ": not a readable Local BA problem: " + problem);
  }

 private:
  std::filesystem::path path_;
  std::ifstream in_;
  std::uint64_t size_ = 0;
};

void put_pose(Writer& w, const Eigen::Isometry3d& T) {
  double p[kPoseParams];
  pose_to_params(T, p);
  for (double x : p) w.put(x);
}

Eigen::Isometry3d get_pose(Reader& r) {
  double p[kPoseParams];
  for (double& x : p) x = r.get<double>("a keyframe pose");
  return params_to_pose(p);
}

}  // namespace

void write_ba_problem(const std::filesystem::path& path, const RecordedBaProblem& rec) {
  Writer w(path);
  w.bytes(kMagic.data(), kMagic.size());
  w.put(kVersion);
  const PinholeCamera& c = rec.camera;
  for (double x : {c.fx, c.fy, c.cx, c.cy, c.k1, c.k2, c.p1, c.p2, c.k3, c.bf}) w.put(x);
  w.put<std::int32_t>(c.width);
  w.put<std::int32_t>(c.height);
  const BaConfig& b = rec.config;
  const KernelConfig& k = b.kernel;
  w.put<std::int32_t>(static_cast<std::int32_t>(k.type));
  for (double x : {k.barron_alpha, k.barron_c, k.tau, k.alpha_max}) w.put(x);
  w.put<std::int32_t>(static_cast<std::int32_t>(k.fit));
  w.put<std::uint8_t>(k.chi2_gates);
  w.put<std::int32_t>(static_cast<std::int32_t>(b.alpha_start));
  for (int x : {b.outer_iterations, b.iterations, b.refine_iterations, b.max_threads}) w.put<std::int32_t>(x);
  w.put<std::uint8_t>(b.remove_outliers);
  const BaProblem& p = rec.problem;
  w.put<std::uint64_t>(p.keyframes.size());
  for (const BaKeyframe& kf : p.keyframes) {
    put_pose(w, kf.T_cw);
    w.put<std::uint8_t>(kf.fixed);
  }
  w.put<std::uint64_t>(p.points.size());
  for (const Eigen::Vector3d& x : p.points)
    for (int i = 0; i < 3; ++i) w.put(x[i]);
  w.put<std::uint64_t>(p.observations.size());
  for (const BaObservation& o : p.observations) {
    w.put<std::int32_t>(o.keyframe);
    w.put<std::int32_t>(o.point);
    for (double x : {o.obs.uv.x(), o.obs.uv.y(), o.obs.u_right, o.obs.inv_sigma2, o.obs.disparity_weight}) w.put(x);
  }
  w.finish();
}

RecordedBaProblem read_ba_problem(const std::filesystem::path& path) {
  Reader r(path);
  std::array<char, 8> magic{};
  r.bytes(magic.data(), magic.size(), "the header");
  if (magic != kMagic) r.fail("it does not start with the Local BA problem header (another kind of file)");
  const auto version = r.get<std::uint32_t>("the header");
  if (version != kVersion)
    r.fail("format version " + std::to_string(version) + "; this build reads version " + std::to_string(kVersion));
  RecordedBaProblem rec;
  PinholeCamera& c = rec.camera;
  for (double* x : {&c.fx, &c.fy, &c.cx, &c.cy, &c.k1, &c.k2, &c.p1, &c.p2, &c.k3, &c.bf}) *x = r.get<double>("the camera");
  c.width = r.get<std::int32_t>("the camera");
  c.height = r.get<std::int32_t>("the camera");
  BaConfig& b = rec.config;
  KernelConfig& k = b.kernel;
  const auto type = r.get<std::int32_t>("the kernel");
  if (type < 0 || type > static_cast<std::int32_t>(KernelType::BarronAdaptive))
    r.fail("kernel type " + std::to_string(type) + " is unknown");
  k.type = static_cast<KernelType>(type);
  for (double* x : {&k.barron_alpha, &k.barron_c, &k.tau, &k.alpha_max}) *x = r.get<double>("the kernel");
  const auto fit = r.get<std::int32_t>("the kernel");
  if (fit < 0 || fit > static_cast<std::int32_t>(robust::AlphaFit::PerComponent))
    r.fail("alpha fit " + std::to_string(fit) + " is unknown");
  k.fit = static_cast<robust::AlphaFit>(fit);
  k.chi2_gates = r.get<std::uint8_t>("the kernel") != 0;
  const auto start = r.get<std::int32_t>("the solver settings");
  if (start < 0 || start > static_cast<std::int32_t>(AlphaStart::SolveFirst))
    r.fail("alpha start " + std::to_string(start) + " is unknown");
  b.alpha_start = static_cast<AlphaStart>(start);
  for (int* x : {&b.outer_iterations, &b.iterations, &b.refine_iterations, &b.max_threads})
    *x = r.get<std::int32_t>("the solver settings");
  b.remove_outliers = r.get<std::uint8_t>("the solver settings") != 0;
  BaProblem& p = rec.problem;
  p.keyframes.resize(r.count("keyframe", kKeyframeBytes));
  for (BaKeyframe& kf : p.keyframes) {
    kf.T_cw = get_pose(r);
    kf.fixed = r.get<std::uint8_t>("a keyframe") != 0;
  }
  p.points.resize(r.count("point", kPointBytes));
  for (Eigen::Vector3d& x : p.points)
    for (int i = 0; i < 3; ++i) x[i] = r.get<double>("a point");
  p.observations.resize(r.count("observation", kObservationBytes));
  const auto keyframes = static_cast<std::int64_t>(p.keyframes.size());
  const auto points = static_cast<std::int64_t>(p.points.size());
  for (std::size_t j = 0; j < p.observations.size(); ++j) {
    BaObservation& o = p.observations[j];
    o.keyframe = r.get<std::int32_t>("an observation");
    o.point = r.get<std::int32_t>("an observation");
    if (o.keyframe < 0 || o.keyframe >= keyframes || o.point < 0 || o.point >= points)
      r.fail("observation " + std::to_string(j) + " names keyframe " + std::to_string(o.keyframe) + " and point " +
             std::to_string(o.point) + ", outside the " + std::to_string(keyframes) + " keyframes and " +
             std::to_string(points) + " points");
    double u = 0, v = 0;
    u = r.get<double>("an observation");
    v = r.get<double>("an observation");
    o.obs.uv = {u, v};
    for (double* x : {&o.obs.u_right, &o.obs.inv_sigma2, &o.obs.disparity_weight}) *x = r.get<double>("an observation");
  }
  if (!r.at_end()) r.fail("bytes after the last observation");
  return rec;
}

}  // namespace varslam::optim
