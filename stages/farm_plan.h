// A farm plan (DESIGN §8): the work of `hairgen run` on a Setup split into tasks a scheduler runs on
// many machines: guides grown in shards and merged, the coupe interpolated in shards and merged, shaded,
// then for a shot simulated and rendered in chunks of frames (each frame interpolated and re-posed in
// memory by `render --guides`, as run does). Every task is a
// hairgen command line with its inputs, outputs, dependencies and CPU and memory requests (from the
// stages' work estimates), and the plan is independent of any scheduler: Slurm is one back end
// (`hairgen farm submit`). Its outputs equal `hairgen run`'s byte for byte.
//
// The plan as JSON (docs/farm-plan.schema.json):
//   {"format": "hairgen-farm-plan", "version": 1, "setup", "directory", "configDigest", "overrides",
//    "shards", "chunk", "frames": {"first", "last"} | null,
//    "tasks": [{"id", "group", "command": [argv], "inputs", "outputs", "deps": [ids], "cpus",
//               "memoryMiB", "estimatedSeconds"}]}
// Tasks of one group (a stage) are alike and may run as one job array; a task's index in its group is
// its order among the group's tasks.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "libcore/config/params.h"
#include "libcore/model/mesh.h"
#include "libcore/util/frames.h"

namespace hairgen {

struct FarmTask {
  std::string id;                    // "grow.3", "merge-guides", "render.2"
  std::string group;                 // "grow", "render": the stage; its tasks differ only in their range
  std::vector<std::string> command;  // argv, argv[0] the hairgen executable
  std::vector<std::string> inputs, outputs;  // files; a sequence's outputs one per frame
  std::vector<std::string> deps;             // ids of the tasks whose outputs this one reads
  int cpus = 1;
  uint64_t memoryMiB = 0;
  double estimatedSeconds = 0.0;  // rough, on this machine's cores
};

struct FarmPlan {
  std::string setup, directory;        // absolute paths
  std::string configDigest;            // of the effective configuration (with the overrides)
  std::vector<std::string> overrides;  // --set and --seed arguments every task gets, as given
  int shards = 1, chunk = 1;
  std::optional<FrameRange> frames;  // a shot's frames; none for a still
  std::vector<FarmTask> tasks;       // in an order that runs: every task after its deps
};

struct FarmPlanOptions {
  std::string hairgen;  // the executable tasks run (absolute)
  std::string setup, directory;
  std::vector<std::string> overrides;  // passed to every stage command that reads the Setup
  int shards = 4;                      // grow and interpolate shards
  int chunk = 5;                       // frames per render task
  int maxCpus = 4;                     // the most CPUs a task asks for
  size_t threads = 1;                  // the threads estimates assume
};

// Plans `config` (the Setup read with the overrides) on `wick`. Throws InputError for a Setup that
// Loads a coupe (no guides to split), a shard or chunk count below 1.
FarmPlan planFarm(const Config& config, const Mesh& wick, const FarmPlanOptions& options);

nlohmann::ordered_json toJson(const FarmPlan& plan);
// Throws InputError naming `name` when the JSON is not a plan of this version.
FarmPlan farmPlanFromJson(const nlohmann::ordered_json& json, const std::string& name);

}  // namespace hairgen
