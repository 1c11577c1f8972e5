#include "report/bench_slurm.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "report/bench_files.hpp"
#include "report/process_pool.hpp"

namespace varslam::report {
namespace fs = std::filesystem;

std::string slurm_array_spec(const std::vector<std::size_t>& numbers) {
  std::string spec;
  for (std::size_t i = 0; i < numbers.size();) {
    std::size_t j = i;
    while (j + 1 < numbers.size() && numbers[j + 1] == numbers[j] + 1) ++j;
    if (!spec.empty()) spec += ',';
    spec += j == i ? fmt::format("{}", numbers[i]) : fmt::format("{}-{}", numbers[i], numbers[j]);
    i = j + 1;
  }
  return spec;
}

std::string slurm_stage_script(const BenchPlan& plan, int stage) {
  const std::vector<std::size_t> jobs = jobs_of_stage(plan, stage);
  if (jobs.empty()) throw InputError(fmt::format("{}: stage {} has no jobs", plan.file().string(), stage));
  // One array shares one limit: the stage's largest, in whole minutes (sbatch --time) and MB (--mem).
  double seconds = 0;
  int memory_mb = 0;
  for (const auto n : jobs) {
    seconds = std::max(seconds, plan.jobs[n].time_limit_seconds);
    memory_mb = std::max(memory_mb, plan.jobs[n].memory_mb);
  }
  const auto minutes = static_cast<long>(std::ceil(seconds / 60.0));
  const fs::path logs = plan.dir / "slurm" / "logs";
  return fmt::format(
      "#!/bin/sh\n"
      "# Stage {stage} of the benchmark plan {plan} (varslam bench plan --slurm): one array task per job, the task\n"
      "# index is the job number. Submit with submit.sh beside this file, which starts stage {next} after it.\n"
      "#SBATCH --job-name=varslam-bench-s{stage}\n"
      "#SBATCH --array={array}\n"
      "#SBATCH --time={minutes}\n"
      "#SBATCH --mem={memory}\n"
      "#SBATCH --cpus-per-task=1\n"
      "#SBATCH --output={logs}/%A_%a.out\n"
      "exec {exe} bench run-job {dir} \"$SLURM_ARRAY_TASK_ID\"\n",
      fmt::arg("stage", stage), fmt::arg("next", stage + 1), fmt::arg("plan", plan.file().string()),
      fmt::arg("array", slurm_array_spec(jobs)), fmt::arg("minutes", minutes), fmt::arg("memory", memory_mb),
      fmt::arg("logs", logs.string()), fmt::arg("exe", shell_quote(plan.executable.string())),
      fmt::arg("dir", shell_quote(plan.dir.string())));
}

fs::path write_slurm_scripts(const BenchPlan& plan) {
  const fs::path dir = plan.dir / "slurm";
  fs::create_directories(dir / "logs");  // sbatch does not create the folder of --output
  std::string submit =
      "#!/bin/sh\n"
      "# Submits the benchmark plan " + plan.file().string() + " to Slurm, one job array per stage; a stage\n"
      "# starts when the one before has ended (afterany: a failed job is recorded, the jobs needing it record\n"
      "# themselves as skipped). Arguments go to every sbatch: --partition=P, --account=A, --wait (return when\n"
      "# the last stage has ended). Then: varslam bench collect " + shell_quote(plan.dir.string()) + "\n"
      "here=$(cd \"$(dirname \"$0\")\" && pwd)\n"
      "previous=\n";
  for (int s = 0; s < stage_count(plan); ++s) {
    write_text_file(dir / fmt::format("stage{}.sbatch", s), slurm_stage_script(plan, s));
    submit += fmt::format(
        "id=$(sbatch --parsable ${{previous:+--dependency=afterany:$previous}} \"$@\" \"$here/stage{0}.sbatch\")\n"
        "id=${{id%%;*}}\n"
        "[ -n \"$id\" ] || {{ echo \"submit.sh: stage {0} was not submitted\" >&2; exit 1; }}\n"
        "echo \"stage {0}: Slurm job $id\"\n"
        "previous=$id\n",
        s);
  }
  write_text_file(dir / "submit.sh", submit);
  fs::permissions(dir / "submit.sh", fs::perms::owner_exec | fs::perms::group_exec | fs::perms::others_exec,
                  fs::perm_options::add);
  return dir / "submit.sh";
}

}  // namespace varslam::report
