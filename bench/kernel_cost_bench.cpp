// Cost of Barron's kernel against Huber inside the SLAM system (issue #5), measured side by side in one run.
//
//  1. End to end: each sequence runs in deterministic mode under three arms, interleaved (the order rotates each
//     repetition, so machine noise and cache warmth hit every arm alike):
//       huber            tracking Huber,        mapping Huber
//       tracking-barron  tracking barron-fixed, mapping Huber            -> (a) tracking median / huber's
//       mapping-adaptive tracking Huber,        mapping barron-adaptive  -> (b) Local BA median / huber's
//  2. Replay: the pose-optimisation and Local BA problems of the first huber run are recorded and solved again
//     under each kernel, alternating per problem. Same inputs for both kernels, so the ratios exclude the
//     trajectory difference of the end-to-end arms; iterations and cost per iteration say where time goes.
//
// Run: build/bin/kernel_cost_bench [--frames N] [--reps R] [--replays K] [SEQUENCE_DIR ...]
// (default sequences: the 7-Scenes kitchen in the shared data and the cached synthetic walking sequence).
#include <fmt/format.h>

#include <algorithm>
#include <ctime>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "eval/ate.hpp"
#include "io/dataset.hpp"
#include "io/trajectory_io.hpp"
#include "optim/local_ba.hpp"
#include "optim/pose_optimizer.hpp"
#include "run/metrics_recorder.hpp"
#include "slam/config.hpp"
#include "slam/system.hpp"

namespace {

namespace fs = std::filesystem;
using namespace varslam;
using optim::KernelType;

struct Options {
  std::size_t frames = 300;
  int reps = 3;
  int replays = 3;
  std::vector<fs::path> sequences;
};

double median(std::vector<double> v) { return run::median_p95(std::move(v)).first; }

double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? 0.0 : s / static_cast<double>(v.size());
}

double sum(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return s;
}

// ---------------------------------------------------------------- end to end

struct Arm {
  std::string name;
  KernelType tracking, mapping;
};

const std::vector<Arm> kArms = {{"huber", KernelType::Huber, KernelType::Huber},
                                {"tracking-barron", KernelType::BarronFixed, KernelType::Huber},
                                {"mapping-adaptive", KernelType::Huber, KernelType::BarronAdaptive}};

/// CPU time of the whole process in milliseconds (every thread the tracking uses; frames are preloaded, so no
/// decoding thread runs meanwhile). The machine is shared: wall time also counts other people's processes.
double process_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

struct ArmRun {
  double tracking_ms = 0;      // median per-frame tracking, wall (what metrics.json reports)
  double tracking_cpu_ms = 0;  // median per-frame CPU time of System::process on frames that made no keyframe
  double pose_ms = 0;          // median per-frame pose optimisation, wall
  double local_ba_ms = 0;      // median Local BA, wall
  double ate_cm = -1;
  std::size_t local_bas = 0;
};

/// The system in deterministic mode over preloaded frames (tracking, then local mapping on each keyframe).
ArmRun run_arm(const std::vector<RgbdFrame>& frames, const Settings& settings, slam::SlamConfig cfg, const Arm& arm,
               const std::optional<Trajectory>& groundtruth) {
  cfg.tracking.kernel.type = arm.tracking;
  cfg.mapping.kernel.type = arm.mapping;
  struct BaTimes final : slam::SystemObserver {
    std::vector<double> ms;
    void on_keyframe_mapped(const slam::KeyframeMapped& m) override {
      if (m.ba) ms.push_back(m.ba->ms);
    }
  } ba_times;
  slam::System system(cfg, settings.camera, settings.close_depth_m(), slam::RunMode::Deterministic, &ba_times);
  std::vector<double> track, track_cpu, pose, ba;
  for (const RgbdFrame& f : frames) {
    const double c0 = process_cpu_ms();
    const slam::TrackOutcome out = system.process(f);
    const double cpu = process_cpu_ms() - c0;
    track.push_back(out.timings.track_ms);
    pose.push_back(out.timings.pose_ms);
    if (!out.keyframe) track_cpu.push_back(cpu);  // a keyframe's process() also ran local mapping
  }
  system.finish();
  ba = ba_times.ms;
  ArmRun r;
  r.tracking_ms = median(track);
  r.tracking_cpu_ms = median(track_cpu);
  r.pose_ms = median(pose);
  r.local_ba_ms = median(ba);
  r.local_bas = ba.size();
  if (groundtruth) {
    try {
      r.ate_cm = 100.0 * evaluate_ate(*groundtruth, system.camera_trajectory()).stats.rmse;
    } catch (const InputError&) {
    }
  }
  return r;
}

// ---------------------------------------------------------------- replay

struct PoseProblem {
  PinholeCamera cam;
  Eigen::Isometry3d T_cw;
  std::vector<Eigen::Vector3d> points;
  std::vector<optim::Observation> obs;
  optim::PoseOptimConfig cfg;
  std::vector<bool> initial_outliers;  // empty = none
};

struct LocalBaProblem {
  PinholeCamera cam;
  optim::BaProblem problem;
  optim::BaConfig cfg;
};

struct Recording {
  std::vector<PoseProblem> poses;
  std::vector<LocalBaProblem> local_bas;
};

/// Makes `cfg` record every optimisation problem of a run into `rec` (copies without the hook, so a replay
/// does not record again).
void record_problems(slam::SlamConfig& cfg, Recording& rec) {
  cfg.tracking.pose_observer = [&rec](const PinholeCamera& cam, const Eigen::Isometry3d& T, const auto& pts,
                                      const auto& obs, const optim::PoseOptimConfig& pc, const auto* init) {
    PoseProblem p{cam, T, pts, obs, pc, init ? *init : std::vector<bool>{}};
    p.cfg.observer = nullptr;
    rec.poses.push_back(std::move(p));
  };
  cfg.mapping.ba_observer = [&rec](const PinholeCamera& cam, const optim::BaProblem& p, const optim::BaConfig& bc) {
    LocalBaProblem l{cam, p, bc};
    l.cfg.observer = nullptr;
    rec.local_bas.push_back(std::move(l));
  };
}

/// CPU time of this thread in milliseconds: the machine is shared, so the replay counts only its own cycles.
double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

/// One replayed solve: thread CPU milliseconds and solver iterations.
struct Solve {
  double ms = 0;
  int iterations = 0;
  int solves = 0;  // Local BA: Ceres solves (each one preprocesses the problem); 0 for pose optimisation
};

Solve replay_pose(const PoseProblem& p, KernelType kernel) {
  optim::PoseOptimConfig cfg = p.cfg;
  cfg.kernel.type = kernel;
  Eigen::Isometry3d T = p.T_cw;
  const double t0 = thread_cpu_ms();
  const optim::PoseOptimResult r =
      optim::optimize_pose(p.cam, T, p.points, p.obs, cfg, p.initial_outliers.empty() ? nullptr : &p.initial_outliers);
  return {thread_cpu_ms() - t0, r.iterations, 0};
}

/// A Local BA variant to replay: how its BaConfig differs from the recorded one.
struct BaVariant {
  std::string name;
  std::function<void(optim::BaConfig&)> apply;
};

Solve replay_local_ba(const LocalBaProblem& p, const BaVariant& v) {
  optim::BaConfig cfg = p.cfg;
  v.apply(cfg);
  optim::BaProblem problem = p.problem;
  const double t0 = thread_cpu_ms();
  const optim::BaResult r = optim::solve_local_ba(p.cam, problem, cfg);
  return {thread_cpu_ms() - t0, r.solver_iterations, r.solves};
}

/// Per arm: the median time of each problem over the replays (arms alternate per problem), and its iterations.
struct ReplayArm {
  std::vector<double> ms;
  std::vector<double> iterations, solves;
};

std::vector<ReplayArm> replay(std::size_t problems, std::size_t arms, int replays,
                              const std::function<Solve(std::size_t problem, std::size_t arm)>& solve) {
  std::vector<ReplayArm> out(arms);
  std::vector<std::vector<double>> times(arms);
  for (std::size_t i = 0; i < problems; ++i) {
    for (auto& t : times) t.clear();
    std::vector<Solve> last(arms);
    for (int k = 0; k < replays; ++k)
      for (std::size_t a = 0; a < arms; ++a) {
        const std::size_t arm = (a + static_cast<std::size_t>(k)) % arms;  // rotate who goes first
        const Solve s = solve(i, arm);
        times[arm].push_back(s.ms);
        last[arm] = s;  // iterations and solves are deterministic: the same every replay
      }
    for (std::size_t a = 0; a < arms; ++a) {
      out[a].ms.push_back(median(times[a]));
      out[a].iterations.push_back(last[a].iterations);
      out[a].solves.push_back(last[a].solves);
    }
  }
  return out;
}

void print_replay(const std::string& what, const std::vector<std::string>& names, const std::vector<ReplayArm>& arms) {
  fmt::print("  replay {} ({} problems, thread CPU time, per-problem median of the replays)\n", what, arms[0].ms.size());
  fmt::print("    {:<28} {:>10} {:>10} {:>10} {:>11} {:>10} {:>10} {:>10}\n", "kernel", "median ms", "total ms",
             "mean iter", "mean solves", "ms / iter", "ratio med", "ratio sum");
  for (std::size_t a = 0; a < arms.size(); ++a) {
    std::vector<double> ratio;
    for (std::size_t i = 0; i < arms[a].ms.size(); ++i) ratio.push_back(arms[a].ms[i] / std::max(arms[0].ms[i], 1e-9));
    const double iters = sum(arms[a].iterations);
    fmt::print("    {:<28} {:>10.3f} {:>10.1f} {:>10.2f} {:>11.2f} {:>10.4f} {:>10.3f} {:>10.3f}\n", names[a],
               median(arms[a].ms), sum(arms[a].ms), mean(arms[a].iterations), mean(arms[a].solves),
               sum(arms[a].ms) / std::max(iters, 1.0), median(ratio),
               sum(arms[a].ms) / std::max(sum(arms[0].ms), 1e-9));
  }
}

// ---------------------------------------------------------------- one sequence

void bench_sequence(const fs::path& dir, const Options& o) {
  const Settings settings = settings_for_dataset(dir, std::nullopt);
  const slam::SlamConfig cfg = slam::slam_config_from(settings);
  const auto dataset = open_dataset(dir, settings);
  fmt::print("\n== {} (first {} frames, {} repetitions)\n", dir.filename().string(), std::min(o.frames, dataset->size()),
             o.reps);

  // 1. End to end, interleaved; the first huber run also records the problems for the replay.
  std::vector<RgbdFrame> frames;
  for (std::size_t i = 0; i < std::min(o.frames, dataset->size()); ++i) frames.push_back(dataset->load(i));
  std::optional<Trajectory> groundtruth;
  if (const auto gt = dataset->groundtruth()) groundtruth = read_tum_trajectory(*gt);
  Recording rec;
  std::vector<std::vector<ArmRun>> runs(kArms.size());
  for (int rep = 0; rep < o.reps; ++rep)
    for (std::size_t a = 0; a < kArms.size(); ++a) {
      const std::size_t arm = (a + static_cast<std::size_t>(rep)) % kArms.size();
      slam::SlamConfig arm_cfg = cfg;
      if (arm == 0 && runs[0].empty()) record_problems(arm_cfg, rec);
      runs[arm].push_back(run_arm(frames, settings, arm_cfg, kArms[arm], groundtruth));
    }
  fmt::print("  end to end (medians over the repetitions of each run's median; ratios within a repetition)\n");
  fmt::print("    {:<18} {:>9} {:>9} {:>8} {:>9} {:>5} {:>7} {:>11} {:>11} {:>10}\n", "arm", "track ms", "track cpu",
             "pose ms", "LBA ms", "LBAs", "ATE cm", "track ratio", "cpu ratio", "LBA ratio");
  for (std::size_t a = 0; a < kArms.size(); ++a) {
    std::vector<double> track, cpu, pose, ba, ate, track_ratio, cpu_ratio, ba_ratio;
    for (std::size_t r = 0; r < runs[a].size(); ++r) {
      const ArmRun& x = runs[a][r];
      const ArmRun& h = runs[0][r];
      track.push_back(x.tracking_ms);
      cpu.push_back(x.tracking_cpu_ms);
      pose.push_back(x.pose_ms);
      ba.push_back(x.local_ba_ms);
      ate.push_back(x.ate_cm);
      track_ratio.push_back(x.tracking_ms / h.tracking_ms);
      cpu_ratio.push_back(x.tracking_cpu_ms / h.tracking_cpu_ms);
      ba_ratio.push_back(x.local_ba_ms / std::max(h.local_ba_ms, 1e-9));
    }
    fmt::print("    {:<18} {:>9.3f} {:>9.3f} {:>8.3f} {:>9.2f} {:>5} {:>7.3f} {:>11.3f} {:>11.3f} {:>10.3f}\n",
               kArms[a].name, median(track), median(cpu), median(pose), median(ba), runs[a][0].local_bas, median(ate),
               median(track_ratio), median(cpu_ratio), median(ba_ratio));
  }

  // 2. Replay of the recorded problems.
  const std::vector<KernelType> pose_kernels = {KernelType::Huber, KernelType::BarronFixed};
  print_replay("pose optimisation", {"huber", "barron-fixed (alpha 1)"},
               replay(rec.poses.size(), pose_kernels.size(), o.replays,
                      [&](std::size_t i, std::size_t a) { return replay_pose(rec.poses[i], pose_kernels[a]); }));
  const auto kernel = [](KernelType t) { return [t](optim::BaConfig& c) { c.kernel.type = t; }; };
  const std::vector<BaVariant> ba_variants = {
      {"huber", kernel(KernelType::Huber)},
      {"barron-adaptive", kernel(KernelType::BarronAdaptive)},
      {"barron-adaptive solve-first",
       [](optim::BaConfig& c) {
         c.kernel.type = KernelType::BarronAdaptive;
         c.alpha_start = optim::AlphaStart::SolveFirst;
       }},
  };
  std::vector<std::string> ba_names;
  for (const auto& v : ba_variants) ba_names.push_back(v.name);
  print_replay("Local BA", ba_names,
               replay(rec.local_bas.size(), ba_variants.size(), o.replays,
                      [&](std::size_t i, std::size_t a) { return replay_local_ba(rec.local_bas[i], ba_variants[a]); }));
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::invalid_argument(a + " needs a value");
      return argv[++i];
    };
    if (a == "--frames") o.frames = std::stoul(value());
    else if (a == "--reps") o.reps = std::stoi(value());
    else if (a == "--replays") o.replays = std::stoi(value());
    else if (a.starts_with("--")) throw std::invalid_argument("unknown option " + a);
    else o.sequences.emplace_back(a);
  }
  if (o.sequences.empty()) {
    o.sequences.push_back(fs::path(VARSLAM_SHARED_DIR) / "realdata/7scenes_redkitchen");
    o.sequences.emplace_back("/tmp/bench_out/sequences/walking__fr2_desk_with_person__s1__3s__at69.5");
  }
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Options o = parse(argc, argv);
    for (const auto& dir : o.sequences) {
      if (!fs::exists(dir)) {
        fmt::print("skipping {}: not found\n", dir.string());
        continue;
      }
      bench_sequence(dir, o);
    }
  } catch (const std::exception& e) {
    fmt::print(stderr, "kernel_cost_bench: {}\n", e.what());
    return 1;
  }
  return 0;
}
