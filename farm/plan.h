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
// Tasks of one group (a stage) are alike and may run as one job array. A group of one task has the
// group's name for its id ("merge-guides"); the tasks of a larger group are GROUP.N, N from 1 (their
// job array index, and the name of their log).
//
// A plan names the commands a farm runs on every node as the user who submits it, so what it may hold
// is checked when one is made (planFarm) and when one is read (farmPlanFromJson), by validateFarmPlan:
//  - a group's name matches [a-z][a-z0-9]*(-[a-z0-9]+)* (at most 64 characters), a task id is its
//    group's name or GROUP.N with N in 1..kFarmMaxGroupTasks (no leading zero);
//  - no string holds a control character (C0 or DEL: a newline, a CR, a NUL);
//  - setup and directory are absolute and normal (no ".", "..", "//" or trailing "/"), the directory
//    not "/"; every output, and every path in a command but the Setup's, lies inside the directory
//    (not its plan.json, slurm/ or logs/, which `farm submit` writes); an input is the Setup or inside
//    the directory (the Setup's mesh and config files are read through the Setup, from where it names);
//  - a command is an executable named hairgen (or hairgen-SUFFIX) by its absolute path, a stage
//    (grow, interpolate, shade, render, simulate, merge, movie), then paths and the options those
//    stages take in a plan: -o --guides --hair --rest --preview --gif (paths), --shard --frames --fps
//    --set --seed, --threads N, --quiet;
//  - counts are bounded: kFarmMaxTasks tasks, kFarmMaxFrames frames, 1..kFarmMaxCpus CPUs a task.
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

// Limits that bound a plan's size and the time to make, read and submit it.
// The most tasks of one group (grow and interpolate shards, render chunks): a group's job array then
// has indices 1..1000, within Slurm's default MaxArraySize (1001).
constexpr int kFarmMaxGroupTasks = 1000;
// The most frames of a plan: a frame names about six files in it (half a kilobyte), and a shot of 10000
// frames is seven minutes at 24 frames a second.
constexpr int kFarmMaxFrames = 10000;
// The most tasks of a plan: three groups at their largest (grow, interpolate, render) and the single
// tasks and simulation chunks.
constexpr size_t kFarmMaxTasks = 3 * kFarmMaxGroupTasks + 16;
// The most CPUs one task asks for (`farm plan --cpus`); and the most memory, far above any node's.
constexpr int kFarmMaxCpus = 4096;
constexpr uint64_t kFarmMaxMemoryMiB = uint64_t(1) << 30;
// The largest plan file `farm submit` reads: a plan at the limits above is 6 MB (with a short folder;
// each path is written some 20000 times), so this leaves room for long paths.
constexpr uint64_t kFarmMaxPlanBytes = uint64_t(64) << 20;

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
// Loads a coupe (no guides to split), shards outside 1..kFarmMaxGroupTasks, a chunk below 1, a shot
// of more than kFarmMaxFrames frames or more than kFarmMaxGroupTasks chunks, and a plan that breaks
// validateFarmPlan (a path with a control character, an executable not named hairgen), naming
// DIRECTORY/plan.json.
FarmPlan planFarm(const Config& config, const Mesh& wick, const FarmPlanOptions& options);

// Throws InputError naming `what` ("--frames") when `frames` runs backwards or holds more than
// kFarmMaxFrames frames.
void checkFarmFrames(const FrameRange& frames, const std::string& what);

// Throws InputError naming `name` (the plan file) and the task for anything the rules above refuse.
void validateFarmPlan(const FarmPlan& plan, const std::string& name);

// Whether `path` (absolute, normal) lies strictly inside the folder `dir` (absolute, normal), by its text:
// the rule validateFarmPlan applies to a plan's paths.
bool isInsideFolder(const std::string& path, const std::string& dir);

// A task's job array index, N of an id GROUP.N; 0 for a group's only task (its id the group's name).
// For a task of a valid plan.
int farmArrayIndex(const FarmTask& task);

nlohmann::ordered_json toJson(const FarmPlan& plan);
// Throws InputError naming `name` when the JSON is not a plan of this version or breaks
// validateFarmPlan's rules; never another exception, whatever the JSON holds.
FarmPlan farmPlanFromJson(const nlohmann::ordered_json& json, const std::string& name);

}  // namespace hairgen
