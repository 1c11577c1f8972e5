#pragma once
// A benchmark plan as Slurm job arrays: one array per stage, whose task indices are the plan's job numbers, each
// task `varslam bench run-job DIR $SLURM_ARRAY_TASK_ID`; a stage starts when the one before has ended.
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "report/bench_plan.hpp"

namespace varslam::report {

/// Writes <plan>/slurm/stage<K>.sbatch per stage (--array the stage's job numbers, --time and --mem the largest
/// of its jobs') and <plan>/slurm/submit.sh, which submits them in order; returns submit.sh.
std::filesystem::path write_slurm_scripts(const BenchPlan& plan);

/// "0-5,8,10-12" for sbatch --array (numbers ascending).
std::string slurm_array_spec(const std::vector<std::size_t>& numbers);

/// The sbatch script of one stage.
std::string slurm_stage_script(const BenchPlan& plan, int stage);

}  // namespace varslam::report
