// The done check every back end shares: a task is done when all its outputs exist and carry the plan's
// config digest, so submitting a plan again redoes only what is missing or stale.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "farm/plan.h"

namespace hairgen::farm {

// Whether `file` exists and was made with `digest`: a .hair's provenance, an EXR's
// hairgen:configDigest; any other file by its presence. An unreadable one is not.
bool carriesDigest(const std::filesystem::path& file, const std::string& digest);

// Whether every output of `task` carries `digest`.
bool taskDone(const FarmTask& task, const std::string& digest);

// taskDone of each of the plan's tasks with its digest, in plan order.
std::vector<bool> doneTasks(const FarmPlan& plan);

}  // namespace hairgen::farm
