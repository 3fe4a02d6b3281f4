// The Slurm back end: a plan's groups of undone tasks as job arrays (sbatch), waited for with squeue.
#pragma once

#include <iosfwd>
#include <memory>

#include "farm/scheduler.h"

namespace hairgen::farm {

// A Slurm scheduler reporting on `out`: each submission's job id, or with dryRun the sbatch lines as a
// shell script (each job id in a variable job_NAME) and nothing submitted.
std::unique_ptr<Scheduler> slurmScheduler(std::ostream& out, bool dryRun);

}  // namespace hairgen::farm
