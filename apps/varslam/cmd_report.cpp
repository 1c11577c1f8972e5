// `varslam report`: one self-contained HTML page for a finished run (plots, numbers, preview image).
#include <fmt/format.h>

#include "cli_common.hpp"
#include "commands.hpp"
#include "io/file_problem.hpp"
#include "io/output_folder.hpp"
#include "report/run_report.hpp"

namespace varslam::cli {

void add_report_command(CLI::App& app) {
  struct Opts {
    std::string run, sequence, out;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("report", "Write a self-contained HTML report (report.html) for a run folder");
  cmd->add_option("--run", o->run, "Run folder written by `varslam run --out`")->required()->check(CLI::ExistingDirectory);
  cmd->add_option("--sequence", o->sequence,
                  "Sequence folder (ground truth, preview.png); default: the dataset recorded in metrics.json")
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--out", o->out, "HTML file to write (default: <run>/report.html)")->check(kNonEmptyPath);
  cmd->callback([o] {
    const std::filesystem::path out = o->out.empty() ? std::filesystem::path(o->run) / "report.html" : std::filesystem::path(o->out.c_str());
    // Into the run folder only over a report of ours; a file the user names with --out is theirs to replace.
    if (o->out.empty())
      claim_output_file(out, "report");
    else
      check_output_file(out, "report");
    report::write_run_report(o->run, o->sequence, out);
    fmt::print("report: wrote {}\n", out.string());
  });
}

}  // namespace varslam::cli
