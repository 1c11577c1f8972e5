// The CLI on broken but plausible input, as a hostile but fair user would try it: each case is a clear error that
// names the file or key (exit 2), a failed run that says why (exit 4), or a run that says what it could not do.
#include <fcntl.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <thread>

#include <fmt/format.h>

#include "cli_runner.hpp"
#include "slam/e2e_support.hpp"

namespace varslam {
namespace {

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::Not;

using cli_test::Outcome;
using cli_test::kCli;
using cli_test::slurp;

Outcome cli(const std::string& args) { return cli_test::cli(args, "varslam_cli"); }

const fs::path& base_sequence() {
  static const fs::path dir = [] {
    synth::SynthConfig cfg;
    cfg.scenario = "walking";
    cfg.seconds = 1.0;
    cfg.seed = 2;
    return slam::e2e::cached_sequence("cli_walking_1s", cfg);
  }();
  return dir;
}

// A private copy of the base sequence to break.
fs::path copy_of_base(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("varslam_cli_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::copy(base_sequence(), d, fs::copy_options::recursive);
  return d;
}

fs::path out_path(const std::string& name) {
  return fs::temp_directory_path() / ("varslam_cli_out_" + name + "_" + std::to_string(::getpid()));
}

// An output folder that does not exist yet.
fs::path out_dir(const std::string& name) {
  fs::remove_all(out_path(name));
  return out_path(name);
}

void append(const fs::path& file, const std::string& text) { std::ofstream(file, std::ios::app) << text; }

std::string run_on(const fs::path& seq, const std::string& name, const std::string& extra = "") {
  return "run -q -d " + seq.string() + " -o " + out_dir(name).string() + " " + extra;
}

// "Billion laughs": ten levels of ten aliases each, 10^10 values to a walk over the tree.
std::string alias_bomb() {
  std::string yaml = "x0: &x0 [a, a, a, a, a, a, a, a, a, a]\n";
  for (int i = 1; i < 10; ++i) {
    yaml += "x" + std::to_string(i) + ": &x" + std::to_string(i) + " [";
    for (int j = 0; j < 10; ++j) yaml += (j ? ", *x" : "*x") + std::to_string(i - 1);
    yaml += "]\n";
  }
  return yaml;
}

struct SettingsCase {
  std::string name, set_args, appended_yaml, expect;
};

class BadSettings : public ::testing::TestWithParam<SettingsCase> {};

// The settings a typo or a bad value used to leave silently at their defaults.
TEST_P(BadSettings, AreAnErrorNamingKeyAndSource) {
  const SettingsCase& c = GetParam();
  fs::path seq = base_sequence();
  if (!c.appended_yaml.empty()) {
    seq = copy_of_base(c.name);
    append(seq / "settings.yaml", c.appended_yaml);
  }
  const Outcome r = cli(run_on(seq, c.name, c.set_args));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr(c.expect));
  if (!c.appended_yaml.empty()) {
    EXPECT_THAT(r.output, HasSubstr("settings.yaml:"));
  }
  if (!c.set_args.empty()) {
    EXPECT_THAT(r.output, HasSubstr("--set '"));
  }
}

INSTANTIATE_TEST_SUITE_P(
    Cli, BadSettings,
    ::testing::Values(
        SettingsCase{"set_key_typo", "--set tracking.kernl=huber", "", "did you mean tracking.kernel?"},
        SettingsCase{"set_section_typo", "--set trackng.kernel=huber", "", "unknown section 'trackng'"},
        SettingsCase{"set_unknown", "--set nosuch.key=1", "", "unknown section 'nosuch'"},
        SettingsCase{"yaml_section_typo", "", "trackng:\n  kernel: huber\n", "did you mean tracking?"},
        SettingsCase{"yaml_key_typo", "", "tracking: {kernl: huber}\n", "did you mean tracking.kernel?"},
        SettingsCase{"yaml_second_camera", "", "camera:\n  fx: 500\n", "'camera' appears twice"},
        SettingsCase{"set_nan", "--set tracking.barron_alpha=.nan", "", "finite"},
        SettingsCase{"set_nan_edge", "--set depth.edge_ratio=.nan", "", "finite"},
        SettingsCase{"set_negative_count", "--set tracking.close_keyframe_gap=-5", "", "[1, 1000000]"},
        SettingsCase{"set_huge_cx", "--set camera.cx=1e300", "", "camera.cx"},
        SettingsCase{"set_broken_yaml", "'--set' 'camera.fx=[1, 2'", "", "not valid YAML"},
        SettingsCase{"set_n_levels", "--set orb.n_levels=1000", "", "[1, 32]"},
        // Settings that were silently ignored: a second spelling of a key, another case, a second document.
        SettingsCase{"yaml_orbslam_fx_beside_ours", "", "Camera1.fx: 600\n", "both give camera.fx"},
        SettingsCase{"yaml_orbslam_depth_factor", "", "RGBD.DepthMapFactor: 1000\n", "both give depth.factor"},
        SettingsCase{"yaml_other_case", "", "Tracking.Kernel: huber\n", "write 'tracking.kernel'"},
        SettingsCase{"yaml_second_document", "", "---\ncamera:\n  fx: 600\n", "a second YAML document"},
        SettingsCase{"yaml_alias_bomb", "", alias_bomb(), "expands to more than 10000 values"}),
    [](const auto& param_info) { return param_info.param.name; });

// A settings file that is there but cannot be read, in the dataset folder or given: an error saying why, never a
// run with the default camera and a warning that there is no settings file.
TEST(BadInput, ASettingsFileThatCannotBeReadIsAnErrorSayingWhy) {
  const fs::path seq = copy_of_base("dangling_settings");
  fs::remove(seq / "settings.yaml");
  fs::create_symlink(seq / "moved.yaml", seq / "settings.yaml");
  const Outcome link = cli(run_on(seq, "dangling_settings"));
  EXPECT_EQ(link.exit_code, 2) << link.output;
  EXPECT_THAT(link.output, AllOf(HasSubstr("settings.yaml: the settings file is a symbolic link to"),
                                 HasSubstr("moved.yaml, which does not exist")));
  EXPECT_THAT(link.output, ::testing::Not(HasSubstr("default settings")));
  const Outcome given = cli(run_on(base_sequence(), "dangling_given", "--settings " + (seq / "settings.yaml").string()));
  EXPECT_EQ(given.exit_code, 2) << given.output;
  EXPECT_THAT(given.output, HasSubstr("which does not exist"));
  fs::remove(seq / "settings.yaml");
  fs::create_directories(seq / "settings.yaml");
  const Outcome folder = cli(run_on(seq, "folder_settings"));
  EXPECT_EQ(folder.exit_code, 2) << folder.output;
  EXPECT_THAT(folder.output, HasSubstr("settings.yaml: is a folder, not a settings file"));
}

// Options that only work beside another were ignored alone; debug frames past the run drew nothing. All are errors
// naming both options (or the frames and the run's range) before any work.
TEST(BadInput, AnOptionWithoutTheOneItNeedsIsAnErrorNamingBoth) {
  const std::string seq = base_sequence().string();
  const std::string gt = seq + "/groundtruth.txt";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {run_on(base_sequence(), "pace_alone", "--pace"), "--pace feeds frames at the dataset's rate in real-time "
                                                        "mode: it only works with --realtime, which is not given"},
      {run_on(base_sequence(), "port_alone", "--viewer-port 8123"), "--viewer-port"},
      {run_on(base_sequence(), "hold_alone", "--viewer-hold"), "--viewer-hold"},
      {"eval --gt " + gt + " --est " + gt + " --per-pair", "--per-pair"},
      {"bench --peer-name other --out " + out_dir("peer_alone").string(), "--peer-name"}};
  for (const auto& [args, flag] : cases) {
    const Outcome o = cli(args);
    EXPECT_EQ(o.exit_code, 2) << args << "\n" << o.output;
    EXPECT_THAT(o.output, AllOf(HasSubstr(flag), HasSubstr("it only works with"))) << args;
  }
  const Outcome beyond = cli(run_on(base_sequence(), "debug_beyond", "-n 5 --debug-frames 2,50,900"));
  EXPECT_EQ(beyond.exit_code, 2) << beyond.output;
  EXPECT_THAT(beyond.output, AllOf(HasSubstr("--debug-frames 50,900: outside the frames this run processes, 0 to 4 "
                                             "of the"),
                                   HasSubstr(base_sequence().string())));
  EXPECT_FALSE(fs::exists(out_path("debug_beyond") / "CameraTrajectory.txt")) << "the run should not have started";
  const Outcome inside = cli(run_on(base_sequence(), "debug_inside", "-n 5 --debug-frames 2"));
  EXPECT_EQ(inside.exit_code, 0) << inside.output;
}

TEST(BadInput, AllZeroDepthIsAFailedRunThatSaysWhy) {
  const fs::path seq = copy_of_base("zero_depth");
  for (const auto& e : fs::directory_iterator(seq / "depth"))
    cv::imwrite(e.path().string(), cv::Mat(480, 640, CV_16UC1, cv::Scalar(0)));
  const Outcome r = cli(run_on(seq, "zero_depth"));
  EXPECT_EQ(r.exit_code, 4) << r.output;
  EXPECT_THAT(r.output, HasSubstr("tracking failed"));
  EXPECT_THAT(r.output, HasSubstr("have a depth"));
  // Asked to accept it: the run stands.
  EXPECT_EQ(cli(run_on(seq, "zero_depth_ok", "--min-tracked-share 0")).exit_code, 0);
}

TEST(BadInput, BlackFramesAreAFailedRunThatSaysWhy) {
  const fs::path seq = copy_of_base("black");
  for (const auto& e : fs::directory_iterator(seq / "rgb"))
    cv::imwrite(e.path().string(), cv::Mat(480, 640, CV_8UC3, cv::Scalar::all(0)));
  const Outcome r = cli(run_on(seq, "black"));
  EXPECT_EQ(r.exit_code, 4) << r.output;
  EXPECT_THAT(r.output, HasSubstr("keypoints"));
  EXPECT_THAT(slurp(out_path("black") / "metrics.json"), HasSubstr("\"status\": \"failed\""));
}

TEST(BadInput, UnwritableMetricsIsAnError) {
  const fs::path out = out_dir("metrics_folder");
  fs::create_directories(out / "metrics.json");  // even empty, a folder of the user's is not removed
  const Outcome r = cli("run -q -d " + base_sequence().string() + " -o " + out.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("metrics.json: cannot write the metrics file: it is a folder"));
}

TEST(BadInput, GroundTruthProblemsAreFoundBeforeTheRun) {
  const fs::path seq = copy_of_base("bad_gt");
  append(seq / "groundtruth.txt", "1 2 3 4 5 6 7\n");
  const fs::path out = out_dir("bad_gt");
  const Outcome r = cli("run -q -d " + seq.string() + " -o " + out.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("groundtruth.txt:"));
  EXPECT_FALSE(fs::exists(out / "CameraTrajectory.txt")) << "the run should not have started";
  const Outcome folder = cli(run_on(base_sequence(), "gt_folder", "--groundtruth " + seq.string()));
  EXPECT_EQ(folder.exit_code, 2) << folder.output;
  EXPECT_THAT(folder.output, HasSubstr("is a folder"));
}

// Every fifth ground-truth pose given twice, the copy 0.5 m off: an ATE against it is garbage, so every command
// that reads ground truth refuses it, naming the file and both lines.
TEST(BadInput, GroundTruthRepeatingAStampWithAnotherPoseIsRefusedEverywhere) {
  const fs::path seq = copy_of_base("repeated_gt");
  std::istringstream in(slurp(base_sequence() / "groundtruth.txt"));
  std::string text, line;
  int lines = 0, first_copy = 0;
  for (int poses = 0; std::getline(in, line);) {
    text += line + "\n";
    ++lines;
    if (line.empty() || line[0] == '#' || ++poses % 5 != 0) continue;
    std::istringstream ss(line);
    std::string stamp;
    double x = 0;
    ss >> stamp >> x;
    std::string rest;
    std::getline(ss, rest);
    text += stamp + " " + std::to_string(x + 0.5) + rest + "\n";
    if (++lines && first_copy == 0) first_copy = lines;
  }
  std::ofstream(seq / "groundtruth.txt") << text;
  const std::string gt = (seq / "groundtruth.txt").string();
  const std::string expect = fmt::format("{}:{}: timestamp", gt, first_copy);
  const std::string both = fmt::format("lines {} and {}", first_copy - 1, first_copy);

  const Outcome run = cli(run_on(seq, "repeated_gt"));
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_THAT(run.output, AllOf(HasSubstr(expect), HasSubstr("is also on line"), HasSubstr(both)));
  const Outcome eval = cli("eval --gt " + gt + " --est " + (base_sequence() / "groundtruth.txt").string());
  EXPECT_EQ(eval.exit_code, 2) << eval.output;
  EXPECT_THAT(eval.output, AllOf(HasSubstr(expect), HasSubstr(both)));
  // The report of a good run drawn against it says so instead of plotting a wrong error.
  const fs::path good = out_dir("repeated_gt_good");
  ASSERT_EQ(cli("run -q -d " + base_sequence().string() + " -o " + good.string()).exit_code, 0);
  const Outcome report = cli("report --run " + good.string() + " --sequence " + seq.string());
  EXPECT_EQ(report.exit_code, 0) << report.output;
  EXPECT_THAT(report.output, HasSubstr(expect));
  EXPECT_THAT(slurp(good / "report.html"), HasSubstr("is also on line"));
}

// A file the system refuses is named with the reason in plain words, wherever it is read or written: a full disk
// (/dev/full), a symlink loop among the frames (skipped like any unreadable frame, not an internal error), a
// permission (below; only testable when not root: root reads everything).
TEST(BadInput, FileProblemsAreNamedInPlainWords) {
  const std::string gt = (base_sequence() / "groundtruth.txt").string();
  const Outcome full = cli("eval --gt " + gt + " --est " + gt + " --json /dev/full");
  EXPECT_EQ(full.exit_code, 2) << full.output;
  EXPECT_THAT(full.output, HasSubstr("/dev/full: cannot write the JSON report: the disk is full"));

  const fs::path seq = copy_of_base("symlink_loop");
  std::vector<fs::path> frames;
  for (const auto& e : fs::directory_iterator(seq / "rgb")) frames.push_back(e.path());
  std::sort(frames.begin(), frames.end());
  const fs::path looped = frames.at(5);
  fs::remove(looped);
  fs::create_symlink(seq / "rgb" / "b", seq / "rgb" / "a");
  fs::create_symlink(seq / "rgb" / "a", seq / "rgb" / "b");
  fs::create_symlink("a", looped);
  const Outcome loop = cli(run_on(seq, "symlink_loop", "--min-tracked-share 0"));
  EXPECT_EQ(loop.exit_code, 0) << loop.output;
  EXPECT_THAT(loop.output, AllOf(HasSubstr(looped.string()), HasSubstr("a loop of symbolic links")));
  EXPECT_THAT(slurp(out_path("symlink_loop") / "metrics.json"), HasSubstr("a loop of symbolic links"));
}

TEST(BadInput, DepthImageWithoutReadPermissionIsSkippedAsPermissionDenied) {
  if (::geteuid() == 0) GTEST_SKIP() << "running as root: permissions cannot be tested";
  const fs::path locked = copy_of_base("locked_depth");
  std::vector<fs::path> depths;
  for (const auto& e : fs::directory_iterator(locked / "depth")) depths.push_back(e.path());
  std::sort(depths.begin(), depths.end());
  fs::permissions(depths.at(3), fs::perms::none);
  const Outcome perm = cli(run_on(locked, "locked_depth", "--min-tracked-share 0"));
  EXPECT_EQ(perm.exit_code, 0) << perm.output;
  EXPECT_THAT(perm.output, AllOf(HasSubstr(depths.at(3).string()), HasSubstr("permission denied")));
  EXPECT_THAT(perm.output, Not(HasSubstr("not a PNG or JPEG")));
}

// An output that cannot be written is found before the run, not after it; an option's bad value is named with
// the option; a message says what is wrong, not a guess (RPE on a short run, the viewer's address, a BOM).
TEST(BadInput, OutputsAreCheckedBeforeTheRunAndOptionsAreNamed) {
  const std::string seq = base_sequence().string();
  struct Case {
    std::string args, expect;
  };
  for (const Case& c : {Case{"--save-map /nonexistent/dir/m.map", "the folder /nonexistent/dir does not exist"},
                        Case{"--save-map " + fs::temp_directory_path().string(), "cannot write the map: it is a folder"},
                        Case{"--save-map /proc/m.map", "cannot create files in /proc"},
                        Case{"-n 0", "--max-frames: expected a whole number of frames, 1 or more, got '0'"},
                        Case{"--first 5000", "--first 5000: the dataset has 30 frames"},
                        Case{"--viewer --viewer-address 999.1.1.1", "--viewer-address: '999.1.1.1' is not an IPv4 address"}}) {
    const fs::path out = out_dir("early");
    const Outcome r = cli("run -q -d " + seq + " -o " + out.string() + " " + c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args << "\n" << r.output;
    EXPECT_THAT(r.output, HasSubstr(c.expect)) << c.args;
    EXPECT_FALSE(fs::exists(out / "CameraTrajectory.txt")) << c.args << ": the run should not have started";
  }
  EXPECT_THAT(cli("run -q -d '' -o " + out_dir("empty_d").string()).output, HasSubstr("--dataset: expected a path"));
  EXPECT_THAT(cli("run -q -d " + seq + " -o ''").output, HasSubstr("--out: expected a path"));

  // Saving the map still fails at the end (a full disk): the metrics and the report are there, the command fails.
  const fs::path out = out_dir("map_full");
  const Outcome full = cli("run -q -d " + seq + " -o " + out.string() + " --save-map /dev/full");
  EXPECT_EQ(full.exit_code, 2) << full.output;
  EXPECT_THAT(full.output, HasSubstr("--save-map: /dev/full: cannot write the map: the disk is full"));
  EXPECT_THAT(slurp(out / "metrics.json"), HasSubstr("the disk is full"));
  EXPECT_TRUE(fs::exists(out / "report.html"));

  // A run shorter than the RPE delta says so (the sequence is 1 s, its poses span 0.97 s).
  EXPECT_THAT(full.output, HasSubstr("too short for RPE at a delta of 1 s: its poses span 0.97 s"));

  // A UTF-8 byte-order mark before rgb.txt's first line (a Windows editor's) is no part of the text.
  const fs::path bom = copy_of_base("bom");
  std::ofstream(bom / "rgb.txt") << "\xEF\xBB\xBF" << slurp(base_sequence() / "rgb.txt");
  const Outcome b = cli(run_on(bom, "bom"));
  EXPECT_EQ(b.exit_code, 0) << b.output;
}

TEST(BadInput, OneFrameRunSaysWhyThereIsNoAte) {
  const Outcome r = cli(run_on(base_sequence(), "one_frame", "-n 1"));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("ATE              not computed: 1 tracked pose (2 needed)"));
}

TEST(BadInput, OutputFolderThatCannotBeCreatedIsAnInputError) {
  const fs::path file = out_dir("a_file");
  std::ofstream(file) << "x";
  const Outcome r = cli("run -q -d " + base_sequence().string() + " -o " + (file / "sub").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("cannot create the output folder"));
}

TEST(BadInput, NegativeFrameCountIsRejected) {
  const Outcome r = cli(run_on(base_sequence(), "negative_n", "-n -1"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.output, HasSubstr("expected a whole number of frames"));
}

TEST(BadInput, AbsurdCoordinatesAndBoxValuesAreRejected) {
  const fs::path dir = out_dir("absurd");
  fs::create_directories(dir);
  std::ofstream(dir / "est.txt") << "1.0 1e300 0 0 0 0 0 1\n2.0 0 0 0 0 0 0 1\n";
  const Outcome eval = cli("eval --gt " + (base_sequence() / "groundtruth.txt").string() + " --est " +
                           (dir / "est.txt").string());
  EXPECT_EQ(eval.exit_code, 2) << eval.output;
  EXPECT_THAT(eval.output, HasSubstr("not a camera position"));
  const fs::path seq = copy_of_base("absurd_boxes");
  append(seq / "boxes.txt", "1311870436.796000 person 0.9 1e300 10 10 10\n");
  const Outcome boxes = cli(run_on(seq, "absurd_boxes", "--set semantic.detector=boxes"));
  EXPECT_EQ(boxes.exit_code, 2) << boxes.output;
  EXPECT_THAT(boxes.output, HasSubstr("out of range"));
}

TEST(BadInput, AnEarlierRunsOutputsAreClearedAndAConcurrentRunIsRefused) {
  const fs::path out = out_dir("reused");
  ASSERT_EQ(cli("run -q -d " + base_sequence().string() + " -o " + out.string()).exit_code, 0);
  ASSERT_TRUE(fs::exists(out / "CameraTrajectory_aligned.txt"));
  std::ofstream(out / "notes.txt") << "mine";
  // A run without ground truth leaves no aligned trajectory: the old one must not stay behind.
  const fs::path seq = copy_of_base("no_gt");
  fs::remove(seq / "groundtruth.txt");
  const std::string old_report = slurp(out / "report.html");
  const Outcome r = cli("run -q -d " + seq.string() + " -o " + out.string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_FALSE(fs::exists(out / "CameraTrajectory_aligned.txt"));
  EXPECT_NE(slurp(out / "report.html"), old_report);
  EXPECT_EQ(slurp(out / "notes.txt"), "mine") << "files that are not ours stay";

  const int fd = ::open((out / ".varslam.lock").c_str(), O_RDWR | O_CREAT, 0644);
  ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);  // as a run in progress holds it
  const Outcome second = cli("run -q -d " + seq.string() + " -o " + out.string());
  ::close(fd);
  EXPECT_EQ(second.exit_code, 2) << second.output;
  EXPECT_THAT(second.output, HasSubstr("another varslam run is writing into this folder"));
}

// Only files a varslam command wrote (its .varslam-outputs lists them) are removed or overwritten; files of the
// user's under an output's name stop every command that writes into a folder, naming the folder and the files.
TEST(BadInput, FilesOfTheUserInAnOutputFolderAreNeverRemoved) {
  const fs::path out = out_dir("users_files");
  fs::create_directories(out);
  for (const char* name : {"report.html", "metrics.json", "semantic_stages_000003.png"}) std::ofstream(out / name) << "mine";
  const Outcome run = cli("run -q -d " + base_sequence().string() + " -o " + out.string() + " --debug-frames 3");
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_THAT(run.output, AllOf(HasSubstr(out.string() + ": holds metrics.json, report.html, semantic_stages_000003.png "
                                                         "that no varslam run wrote there"),
                                HasSubstr("give another --out")));
  for (const char* name : {"report.html", "metrics.json", "semantic_stages_000003.png"})
    EXPECT_EQ(slurp(out / name), "mine") << name;
  EXPECT_FALSE(fs::exists(out / "CameraTrajectory.txt")) << "the run should not have started";

  // The same for a report written into a folder of the user's, and for a benchmark's summary files.
  const fs::path run_dir = out_dir("users_report");
  ASSERT_EQ(cli("run -q -d " + base_sequence().string() + " -o " + run_dir.string()).exit_code, 0);
  fs::remove(run_dir / ".varslam-outputs");
  const Outcome report = cli("report --run " + run_dir.string());
  EXPECT_EQ(report.exit_code, 2) << report.output;
  EXPECT_THAT(report.output, HasSubstr(run_dir.string() + ": holds report.html that no varslam run wrote there"));
  const fs::path bench = out_dir("users_bench");
  fs::create_directories(bench);
  std::ofstream(bench / "table.md") << "mine";
  const Outcome b = cli("bench --scenarios static --paths builtin --seeds 1 --seconds 0.5 --configs huber -j 1 --out " +
                        bench.string());
  EXPECT_EQ(b.exit_code, 2) << b.output;
  EXPECT_THAT(b.output, HasSubstr(bench.string() + ": holds table.md that no varslam run wrote there"));
  EXPECT_EQ(slurp(bench / "table.md"), "mine");
}

TEST(BadInput, SigintStopsTheRunCleanlyAndKeepsWhatWasTracked) {
  synth::SynthConfig cfg;
  cfg.scenario = "static";
  cfg.seconds = 6.0;
  cfg.seed = 2;
  const fs::path seq = slam::e2e::cached_sequence("cli_static_6s", cfg);
  const fs::path out = out_dir("sigint");
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const std::string log = out.string() + ".log";
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    ::execl(kCli.c_str(), kCli.c_str(), "run", "-q", "--realtime", "--pace", "-d", seq.c_str(), "-o", out.c_str(),
            static_cast<char*>(nullptr));
    ::_exit(127);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(2500));  // past start-up, a few seconds into the sequence
  const auto sent = std::chrono::steady_clock::now();
  ::kill(pid, SIGINT);
  int status = 0;
  ::waitpid(pid, &status, 0);
  const double stop_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count();
  ASSERT_TRUE(WIFEXITED(status)) << slurp(out.string() + ".log");
  EXPECT_EQ(WEXITSTATUS(status), 130) << slurp(out.string() + ".log");
  EXPECT_LT(stop_s, 2.0) << "stopping took " << stop_s << " s";
  const std::string metrics = slurp(out / "metrics.json");
  EXPECT_THAT(metrics, HasSubstr("\"status\": \"interrupted\""));
  const std::string traj = slurp(out / "CameraTrajectory.txt");
  const auto lines = std::count(traj.begin(), traj.end(), '\n');
  EXPECT_GT(lines, 10);
  EXPECT_LT(lines, 170) << "the whole sequence was run";
}

// README's command 1 runs `varslam demo` from the checkout with a relative --out: its person boxes must be found.
TEST(BadInput, MapOptionsAreCheckedBeforeTheRun) {
  const Outcome alone = cli(run_on(base_sequence(), "loc_only", "--localization-only"));
  EXPECT_EQ(alone.exit_code, 2) << alone.output;
  EXPECT_THAT(alone.output, HasSubstr("--localization-only needs a map to localize in"));
  const fs::path not_a_map = out_path("not_a_map.map");
  std::ofstream(not_a_map) << "camera:\n  fx: 500\n";
  const Outcome bad = cli(run_on(base_sequence(), "bad_map", "--load-map " + not_a_map.string()));
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_THAT(bad.output, HasSubstr(not_a_map.string() + ": not a varslam map"));
  const Outcome missing = cli(run_on(base_sequence(), "missing_map", "--load-map /nonexistent/x.map"));
  EXPECT_EQ(missing.exit_code, 2) << missing.output;
  EXPECT_THAT(missing.output, HasSubstr("/nonexistent/x.map: map file not found"));
}

// Every number option is finite and in its range, and the error names the option (CLI11's ranges let NaN through).
TEST(BadInput, NonFiniteOrOutOfRangeNumberOptionsAreRefusedByName) {
  const std::string seq = base_sequence().string();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"run -q -d " + seq + " -o " + out_dir("nan_share").string() + " --min-tracked-share nan", "--min-tracked-share"},
      {"run -q -d " + seq + " -o " + out_dir("nan_fps").string() + " --viewer-fps nan", "--viewer-fps"},
      {"eval --gt " + seq + "/groundtruth.txt --est " + seq + "/groundtruth.txt --offset nan", "--offset"},
      {"eval --gt " + seq + "/groundtruth.txt --est " + seq + "/groundtruth.txt --delta -1", "--delta"},
      {"synth --seconds inf --out " + out_dir("inf_synth").string(), "--seconds"},
      {"synth --box-miss 2 --out " + out_dir("miss_synth").string(), "--box-miss"},
      {"bag-from-folder -d " + seq + " -o " + out_path("x.bag").string() + " --time-offset nan", "--time-offset"}};
  for (const auto& [args, option] : cases) {
    const Outcome o = cli(args);
    EXPECT_EQ(o.exit_code, 2) << args << "\n" << o.output;
    EXPECT_THAT(o.output, HasSubstr(option)) << args;
  }
}

// Bags as input (varslam run --dataset FILE.bag): each broken bag is an error naming the bag and what is wrong.
TEST(BadInput, BadBagsAreNamedErrors) {
  const fs::path dir = out_dir("bags");
  fs::create_directories(dir);
  const fs::path bag = dir / "good.bag";
  const Outcome made = cli("bag-from-folder -d " + base_sequence().string() + " -o " + bag.string() + " --images png");
  if (made.output.find("built without ROS bag support") != std::string::npos) GTEST_SKIP() << "no ROS in this build";
  ASSERT_EQ(made.exit_code, 0) << made.output;
  const Outcome ok = cli("run -q -d " + bag.string() + " -o " + (dir / "ok").string() + " --gt-frame kinect");
  EXPECT_EQ(ok.exit_code, 0) << ok.output;
  EXPECT_THAT(ok.output, AllOf(HasSubstr("camera from CameraInfo /camera/rgb/camera_info"), HasSubstr("ATE")));

  std::ofstream(dir / "text.bag") << "1.0 rgb/1.png\n";
  const Outcome text = cli("run -q -d " + (dir / "text.bag").string() + " -o " + (dir / "o1").string());
  EXPECT_EQ(text.exit_code, 2) << text.output;
  EXPECT_THAT(text.output, HasSubstr("text.bag: not a ROS bag"));

  const std::string bytes = slurp(bag);
  std::ofstream(dir / "cut.bag", std::ios::binary) << bytes.substr(0, bytes.size() * 2 / 3);
  const Outcome cut = cli("run -q -d " + (dir / "cut.bag").string() + " -o " + (dir / "o2").string());
  EXPECT_EQ(cut.exit_code, 2) << cut.output;
  EXPECT_THAT(cut.output, AllOf(HasSubstr("cut.bag: the bag is"), HasSubstr("not indexed"), HasSubstr("rosbag reindex")));

  const Outcome topic = cli("run -q -d " + bag.string() + " -o " + (dir / "o3").string() + " --topic-rgb /camera/x");
  EXPECT_EQ(topic.exit_code, 2) << topic.output;
  EXPECT_THAT(topic.output, AllOf(HasSubstr("--topic-rgb /camera/x is not in the bag"),
                                  HasSubstr("/camera/rgb/image_color/compressed (sensor_msgs/CompressedImage")));

  const Outcome gt = cli("run -q -d " + bag.string() + " -o " + (dir / "o4").string() + " --gt-frame body");
  EXPECT_EQ(gt.exit_code, 2) << gt.output;
  EXPECT_THAT(gt.output, HasSubstr("--gt-frame body: no transform in /tf or /tf_static has child frame 'body'"));

  const Outcome folder = cli(run_on(base_sequence(), "topic_on_folder", "--topic-rgb /camera/rgb/image_color"));
  EXPECT_EQ(folder.exit_code, 2) << folder.output;
  EXPECT_THAT(folder.output, HasSubstr("are for .bag input"));
  fs::remove_all(dir);
}

TEST(Demo, RunsFromARelativeFolderWithThePersonFilter) {
  const fs::path dir = out_dir("demo_cwd");
  fs::create_directories(dir);
  const std::string cmd = "cd " + dir.string() + " && " + kCli + " demo --seconds 1 --out out/demo > demo.log 2>&1";
  const int status = std::system(cmd.c_str());
  const std::string log = slurp(dir / "demo.log");
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << log;
  EXPECT_THAT(log, HasSubstr("ATE              rmse"));
  EXPECT_THAT(slurp(dir / "out/demo/run/metrics.json"), HasSubstr("\"detector\": \"boxes(boxes.txt)\""));
}

}  // namespace
}  // namespace varslam
