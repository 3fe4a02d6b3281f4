// What a farm back end does with a plan (farm/plan.h): hand its tasks that are not done to a
// scheduler, each after the tasks it reads, then optionally wait for them. Slurm is one
// (farm/slurm.h); a Deadline or OpenCue back end would be another. The done set comes from
// farm/done.h, the same for every back end, so a scheduler never decides what is done.
#pragma once

#include <cstddef>
#include <vector>

#include "farm/plan.h"

namespace hairgen::farm {

class Scheduler {
 public:
  virtual ~Scheduler() = default;

  // Submits plan.tasks[i] for each i where done[i] is false (done has one entry per task), each to
  // start after the undone tasks it depends on; a done dependency is not waited for. Reports what it
  // submitted on the stream it was made with. Returns how many tasks it submitted (0: nothing to do).
  virtual size_t submit(const FarmPlan& plan, const std::vector<bool>& done) = 0;

  // Returns when every task the last submit handed over has finished, reporting on its stream that
  // the plan is done; throws IoError naming the first task that did not finish, and its log.
  virtual void wait(const FarmPlan& plan) = 0;
};

}  // namespace hairgen::farm
