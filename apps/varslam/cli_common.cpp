#include <algorithm>
#include <cmath>
#include "cli_common.hpp"

#include <fmt/format.h>

#include <arpa/inet.h>
#include <netdb.h>
#include <signal.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <stdexcept>
#include <thread>

#include "core/error.hpp"
#include "report/run_report.hpp"

namespace varslam::cli {
namespace {

// Set by SIGINT / SIGTERM: the one piece of process-wide state a signal handler needs.
std::atomic<bool> g_stop_requested{false};
extern "C" void request_stop(int) { g_stop_requested.store(true); }

}  // namespace

const std::atomic<bool>& stop_on_signals() {
  struct sigaction sa {};
  sa.sa_handler = request_stop;
  sa.sa_flags = SA_RESETHAND;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  return g_stop_requested;
}

void wait_for_stop() {
  while (!g_stop_requested.load()) std::this_thread::sleep_for(std::chrono::milliseconds(100));
}

const CLI::Validator kNonEmptyPath(
    [](std::string& v) { return v.empty() ? std::string("expected a path, got an empty string") : std::string(); },
    "PATH");

namespace {
std::string whole_number_at_least(const std::string& v, int least) {
  const bool digits = !v.empty() && v.find_first_not_of("0123456789") == std::string::npos;
  if (digits && (least == 0 || v.find_first_not_of('0') != std::string::npos)) return {};
  return fmt::format("expected a whole number of frames, {} or more, got '{}'", least, v);
}

// A dotted quad out of range (999.1.1.1) would otherwise go to the resolver as a host name.
bool looks_like_ipv4(const std::string& v) { return !v.empty() && v.find_first_not_of("0123456789.") == std::string::npos; }
}  // namespace

const CLI::Validator kFrameIndex([](std::string& v) { return whole_number_at_least(v, 0); }, "INDEX");
const CLI::Validator kFrameCount([](std::string& v) { return whole_number_at_least(v, 1); }, "COUNT");

const CLI::Validator kListenAddress(
    [](std::string& v) -> std::string {
      in_addr a4{};
      in6_addr a6{};
      if (::inet_pton(AF_INET, v.c_str(), &a4) == 1 || ::inet_pton(AF_INET6, v.c_str(), &a6) == 1) return {};
      const std::string hint = "; use an address of this machine, e.g. 127.0.0.1, 0.0.0.0 (all) or ::1";
      if (looks_like_ipv4(v)) return "'" + v + "' is not an IPv4 address (four numbers from 0 to 255)" + hint;
      addrinfo hints{};
      hints.ai_flags = AI_PASSIVE;
      hints.ai_socktype = SOCK_STREAM;
      addrinfo* found = nullptr;
      if (::getaddrinfo(v.c_str(), nullptr, &hints, &found) != 0)
        return "'" + v + "' is neither an IP address nor a host name that resolves" + hint;
      ::freeaddrinfo(found);
      return {};
    },
    "ADDRESS");

void check_first_frame(std::size_t first, std::size_t frames) {
  if (first < frames) return;
  throw InputError(fmt::format("--first {}: the dataset has {} frames, so --first is at most {}", first, frames,
                               frames == 0 ? 0 : frames - 1));
}

void check_flag_needs(const CLI::App& app) {
  for (const CLI::App* cmd : app.get_subcommands())  // the ones given on the command line
    for (const FlagNeed& n : kFlagNeeds) {
      if (cmd->get_name() != n.command) continue;
      const CLI::Option* flag = cmd->get_option_no_throw(std::string(n.flag));
      const CLI::Option* needs = cmd->get_option_no_throw(std::string(n.needs));
      if (!flag || !needs)
        throw std::logic_error(fmt::format("kFlagNeeds: `{}` has no option {} or {}", n.command, n.flag, n.needs));
      if (flag->count() > 0 && needs->count() == 0)
        throw InputError(fmt::format("{} {}: it only works with {}, which is not given", n.flag, n.what, n.needs));
    }
}

CLI::Validator finite_range(double lo, double hi, bool lo_open) {
  return CLI::Validator(
      [=](std::string& v) -> std::string {
        double x = 0;
        std::size_t used = 0;
        try {
          x = std::stod(v, &used);
        } catch (const std::exception&) {
          return "expected a number, got '" + v + "'";
        }
        if (used != v.size()) return "expected a number, got '" + v + "'";
        if (!std::isfinite(x)) return "expected a finite number, got '" + v + "'";
        if (x < lo || x > hi || (lo_open && x == lo))
          return fmt::format("{} is outside {}{}, {}]", v, lo_open ? "(" : "[", lo, hi);
        return {};
      },
      fmt::format("NUMBER in {}{}, {}]", lo_open ? "(" : "[", lo, hi));
}

void write_report_for_run(const std::filesystem::path& run_dir, const std::filesystem::path& sequence_dir) {
  try {
    report::write_run_report(run_dir, sequence_dir, run_dir / "report.html");
  } catch (const std::exception& e) {
    spdlog::warn("report not written: {}", e.what());
  }
}

void print_run_summary(const run::RunSummary& s) {
  fmt::print("frames           {}\n", s.frames);
  fmt::print("tracked          {} ({:.1f}%), lost {}, map segments {}\n", s.tracked,
             s.frames ? 100.0 * s.tracked / s.frames : 0.0, s.lost, s.segments);
  fmt::print("map              {} keyframes, {} points\n", s.keyframes, s.map_points);
  if (s.metrics.contains("loops") && s.metrics.contains("relocalizations"))
    fmt::print("loops closed     {}, relocalizations {}\n", s.metrics["loops"].size(),
               s.metrics["relocalizations"].get<int>());
  fmt::print("speed            {:.1f} frames/s over {:.1f} s\n", s.fps, s.wall_seconds);
  if (s.metrics.contains("timings")) {
    const auto& t = s.metrics["timings"];
    fmt::print("tracking median  {:.2f} ms (extract {:.2f}, match {:.2f}, pose {:.2f}); local BA median {:.1f} ms\n",
               t["tracking"]["median_ms"].get<double>(), t["extract"]["median_ms"].get<double>(),
               t["match"]["median_ms"].get<double>(), t["pose_optimization"]["median_ms"].get<double>(),
               t["local_ba"]["median_ms"].get<double>());
  }
  if (s.metrics.contains("semantic") && s.metrics["semantic"].value("detector_runs", 0) > 0) {
    const auto& m = s.metrics["semantic"];
    fmt::print("person boxes     {} ran on {} frames; box age median {:.0f} ms, p95 {:.0f}; {:.1f} % of frames had boxes "
               "at most two frames old (30 Hz)\n",
               m["detector"].get<std::string>(), m["detector_runs"].get<long>(), m["box_age"]["median_ms"].get<double>(),
               m["box_age"]["p95_ms"].get<double>(), 100.0 * m.value("fresh_box_share", 0.0));
  }
  // Deterministic mode waits for the detector (semantic.deterministic_detect_every / _lag): on a slow machine that,
  // not SLAM, sets the speed. Say so, and what runs faster, where a user would otherwise wonder.
  if (s.metrics.value("mode", "") == "deterministic" && s.metrics.contains("semantic") && s.fps < 20.0 &&
      s.metrics["semantic"].value("detector_runs", 0) > 0) {
    const double detector_ms = s.metrics["semantic"]["detector_latency"]["median_ms"].get<double>();
    if (detector_ms > 0.5 * 1000.0 / std::max(s.fps, 1e-9))
      fmt::print("note             the person detector took {:.0f} ms per run and deterministic mode waits for it; "
                 "--realtime never waits for it\n",
                 detector_ms);
  }
  if (s.metrics.contains("realtime")) {
    const auto& r = s.metrics["realtime"];
    fmt::print("real time        latency median {:.1f} ms, p95 {:.1f} (frame in to pose out); frames late {}, dropped {} "
               "(a newer one had arrived); mapping queue median {:.0f}, max {:.0f}; Local BA skipped on {} and cut "
               "short on {} of {} keyframes\n",
               r["latency"]["median_ms"].get<double>(), r["latency"]["p95_ms"].get<double>(),
               r["late_frames"].get<long>(), r["dropped_frames"].get<long>(), r["mapping_queue"]["median"].get<double>(),
               r["mapping_queue"]["max"].get<double>(), r["local_ba_skipped"].get<long>(),
               r["local_ba_cut_short"].get<long>(), r["keyframes_mapped"].get<long>());
  }
  if (s.ate_rmse)
    fmt::print("ATE              rmse {:.2f} cm, max {:.2f} cm\n", *s.ate_rmse * 100.0, *s.ate_max * 100.0);
  else if (!s.ate_note.empty())
    fmt::print("ATE              {}\n", s.ate_note);
  else
    fmt::print("ATE              (no ground truth)\n");
  if (s.ate_live_rmse)
    fmt::print("live ATE         rmse {:.2f} cm, max {:.2f} cm, dragged {} time(s) (> 10 cm off within 1 s)\n",
               *s.ate_live_rmse * 100.0, *s.ate_live_max * 100.0, s.dragged_events);
  if (s.ate_map_frame_rmse)
    fmt::print("ATE in map frame rmse {:.2f} cm, max {:.2f} cm (the loaded map's alignment to ground truth)\n",
               *s.ate_map_frame_rmse * 100.0, *s.ate_map_frame_max * 100.0);
  fmt::print("trajectory       {}\n", (s.out_dir / "CameraTrajectory.txt").string());
  fmt::print("metrics          {}\n", (s.out_dir / "metrics.json").string());
  fmt::print("map              {}\n", (s.out_dir / "map.ply").string());
  if (std::filesystem::exists(s.out_dir / "report.html"))
    fmt::print("report           {}\n", (s.out_dir / "report.html").string());
}

}  // namespace varslam::cli
