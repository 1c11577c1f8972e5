#pragma once
// Helpers shared by the subcommands: settings overrides from the command line, summary printing.
#include <CLI/CLI.hpp>
#include <atomic>
#include <string>
#include <string_view>
#include <vector>

#include "io/settings.hpp"
#include "io/settings_registry.hpp"
#include "run/dataset_run.hpp"

namespace varslam::cli {

/// An option that only means something beside another one: alone it would be ignored, so it is an error.
struct FlagNeed {
  std::string_view command;  // the subcommand both belong to
  std::string_view flag;     // given alone it would do nothing...
  std::string_view needs;    // ...without this one
  std::string_view what;     // what `flag` does, for the message
};

// Every such pair of every subcommand, checked in one place (check_flag_needs).
inline constexpr FlagNeed kFlagNeeds[] = {
    {"run", "--pace", "--realtime", "feeds frames at the dataset's rate in real-time mode"},
    {"run", "--drop-late", "--pace", "drops frames a newer one has overtaken, as a live sensor does"},
    {"run", "--viewer-port", "--viewer", "sets the live viewer's port"},
    {"run", "--viewer-address", "--viewer", "sets the live viewer's address"},
    {"run", "--viewer-fps", "--viewer", "limits the frames sent to the live viewer"},
    {"run", "--viewer-dense-rate", "--viewer", "limits the live viewer's dense map updates"},
    {"run", "--viewer-hold", "--viewer", "keeps the live viewer up after the run"},
    {"run", "--viewer-wait", "--viewer", "waits for a browser at the live viewer"},
    {"run", "--localization-only", "--load-map", "needs a map to localize in"},
    {"eval", "--per-pair", "--json", "puts each pair's error into the JSON file"},
    {"bench", "--peer-trajectory", "--peer", "names the trajectory file the peer writes"},
    {"bench", "--peer-name", "--peer", "names the peer's column"},
};

/// Throws InputError naming both options when a parsed subcommand has an option of kFlagNeeds without the one it
/// needs; std::logic_error when the table names an option the subcommand does not have.
void check_flag_needs(const CLI::App& app);

/// A number option's check: finite (CLI11's own ranges let NaN through) and within [lo, hi] (or (lo, hi] when
/// `lo_open`); the error names the value and the range, and CLI11 names the option.
CLI::Validator finite_range(double lo, double hi, bool lo_open = false);

/// A path option's check: not empty ('' would mean the current folder or nothing, silently); CLI11 names the option.
extern const CLI::Validator kNonEmptyPath;

/// Frame indices (0 or more) and frame counts (1 or more): CLI11 would wrap "-1" around to the largest size_t.
extern const CLI::Validator kFrameIndex;
extern const CLI::Validator kFrameCount;

/// An address to listen on: an IPv4 or IPv6 address, or a host name that resolves ("999.1.1.1" is neither).
extern const CLI::Validator kListenAddress;

/// InputError naming --first when it is not a frame of a dataset of `frames` frames.
void check_first_frame(std::size_t first, std::size_t frames);

/// Writes <run>/report.html (plots of the trajectory, error, alpha per keyframe, timings); a failure is a warning.
void write_report_for_run(const std::filesystem::path& run_dir, const std::filesystem::path& sequence_dir);

/// The first SIGINT or SIGTERM from now on sets the returned flag (a command then ends cleanly, writing what it
/// has); a second one kills at once.
const std::atomic<bool>& stop_on_signals();

/// Blocks until stop_on_signals()' flag is set.
void wait_for_stop();

/// One human-readable block: frames, tracking share, keyframes, speed, ATE, and where the files went.
void print_run_summary(const run::RunSummary& s);

}  // namespace varslam::cli
