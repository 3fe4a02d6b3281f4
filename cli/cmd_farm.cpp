// hairgen farm plan SETUP -o DIR | submit PLAN --scheduler slurm [--wait] [--dry-run]: the work of
// `hairgen run` split into tasks (farm/plan.h), and the plan handed to a scheduler (farm/: the
// done check every back end shares, the Slurm back end, the process runner and the shell quoting).
//
// A task is done when all its outputs exist and carry the plan's config digest (farm/done.h), so
// submitting a plan again redoes only what is missing or stale. Every output is written atomically, so
// a task killed mid-way leaves nothing that passes for done.
//
// A plan is input: farmPlanFromJson checks it by validateFarmPlan's rules, and its data reaches the
// scripts and the printed dry run only through farm/shell.h.
#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>

#include <tbb/task_arena.h>

#include "cli/commands.h"
#include "cli/common.h"
#include "farm/done.h"
#include "farm/plan.h"
#include "farm/slurm.h"
#include "libcore/io/obj_io.h"
#include "libcore/util/file_util.h"
#include "libcore/util/json.h"

namespace hairgen::cli {
namespace {

namespace fs = std::filesystem;

std::string executablePath() {
  std::error_code ec;
  fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw IoError("cannot find the hairgen executable (/proc/self/exe): " + ec.message());
  return exe.string();
}

// The plan's configuration read again, as its tasks will read it: a Setup, Info file, mesh or shader
// edited since the plan was made gives another digest, and the tasks' outputs would never carry the
// plan's (every task rerun at each submit, --wait reporting tasks that succeeded as failed).
void requireUnchangedConfig(const FarmPlan& plan, const std::string& planFile) {
  CommonOptions asPlanned;
  for (size_t i = 0; i + 1 < plan.overrides.size(); i += 2) {
    if (plan.overrides[i] == "--set") asPlanned.sets.push_back(plan.overrides[i + 1]);
    if (plan.overrides[i] == "--seed") asPlanned.seed = std::stoull(plan.overrides[i + 1]);  // validated
  }
  const std::string now = loadConfig(plan.setup, parseOverrides(asPlanned), SetupUse::kRun).digest();
  if (now != plan.configDigest)
    throw InputError({planFile, 0},
                     "the Setup or a file it names has changed since this plan was made (config " + now +
                         " now, " + plan.configDigest +
                         " planned); make the plan again with `hairgen farm plan`");
}

// A plan is read from the folder it names: its tasks write there and submit writes its scripts and logs
// there, so a plan file placed elsewhere cannot direct them into another folder.
void requirePlanInItsDirectory(const FarmPlan& plan, const std::string& planFile) {
  std::error_code ec;
  const fs::path folder = fs::absolute(planFile).parent_path();
  if (!fs::equivalent(folder, plan.directory, ec))
    throw InputError({planFile, 0}, "names the directory " + plan.directory +
                                        ", not the folder it is in; submit DIR/plan.json from the DIR "
                                        "`hairgen farm plan -o DIR` wrote");
}

// A plan runs the hairgen that submits it: each task's executable must be this very file (by device and
// inode, however it is named), or a plan from elsewhere could name any program called hairgen (one it
// put in its own folder). The tasks then run this executable by the name the system gives it, so a file
// swapped in at the plan's name later runs nothing either. Returns the plan so.
FarmPlan runningThisHairgen(FarmPlan plan, const std::string& planFile) {
  const std::string self = executablePath();
  struct stat mine {};
  if (::stat(self.c_str(), &mine) != 0)
    throw IoError("cannot examine the hairgen executable " + self + ": " + std::strerror(errno));
  for (FarmTask& t : plan.tasks) {
    struct stat st {};
    if (::stat(t.command[0].c_str(), &st) != 0 || st.st_dev != mine.st_dev || st.st_ino != mine.st_ino)
      throw InputError({planFile, 0}, "task \"" + t.id + "\": its executable " + t.command[0] +
                                          " is not this hairgen (" + self +
                                          "); a plan runs the hairgen that submits it: make the plan "
                                          "again with `hairgen farm plan`, or submit it with the "
                                          "hairgen that made it");
    t.command[0] = self;
  }
  return plan;
}

// The plan's folder holds its files itself: no symbolic link on the way from the folder to a file it
// names (an input's own name included), nor at slurm/ and logs/, where submit writes. A link planted in
// a plan's folder would send a task's writes, or submit's scripts, into any folder, or feed a task a
// file from anywhere as its input; the paths' text alone (validateFarmPlan) cannot see that.
void requireNoLinksInPlan(const FarmPlan& plan, const std::string& planFile) {
  const fs::path dir(plan.directory);
  auto check = [&](const std::string& path, bool lastToo, const std::string& what) {
    const fs::path relative = fs::path(path).lexically_relative(dir);
    fs::path walked = dir;
    size_t parts = size_t(std::distance(relative.begin(), relative.end()));
    for (const fs::path& part : relative) {
      walked /= part;
      if (--parts == 0 && !lastToo) return;
      struct stat st {};
      if (::lstat(walked.c_str(), &st) != 0) return;  // not there yet: the task makes it
      if (S_ISLNK(st.st_mode))
        throw InputError({planFile, 0}, what + " " + path + ": " + walked.string() +
                                            " is a symbolic link; a plan's files lie in its folder "
                                            "itself, not behind links");
    }
  };
  // submit's folders, and what submit (and Slurm, for a task's log, which it opens following links)
  // writes in them: no entry may be a link either.
  for (const auto& [folder, what] :
       {std::pair{"/slurm", "submit's scripts"}, std::pair{"/logs", "submit's logs"}}) {
    check(plan.directory + folder, true, what);
    std::error_code ec;
    fs::directory_iterator it(plan.directory + folder, ec), end;
    for (; !ec && it != end; it.increment(ec))
      if (it->is_symlink(ec))
        throw InputError({planFile, 0}, it->path().string() +
                                            " is a symbolic link; submit and Slurm write there, and a plan's "
                                            "files lie in its folder itself, not behind links");
    if (ec && ec != std::errc::no_such_file_or_directory)  // one it cannot list may hide a link
      throw InputError({planFile, 0}, plan.directory + folder + " cannot be listed (" + ec.message() +
                                          "); submit checks what it and Slurm write there");
  }
  for (const FarmTask& t : plan.tasks) {
    const std::string task = "task \"" + t.id + "\":";
    for (const std::string& o : t.outputs) check(o, false, task + " output");
    for (const std::string& i : t.inputs)
      if (isInsideFolder(i, plan.directory)) check(i, true, task + " input");
    for (size_t k = 2; k < t.command.size(); ++k)
      if (isInsideFolder(t.command[k], plan.directory))
        check(t.command[k],
              t.command[k - 1] != "-o" && t.command[k - 1] != "--preview" && t.command[k - 1] != "--gif",
              task + " command path");
  }
}

// Hands the plan's undone tasks to the scheduler (Slurm, the only one yet) and, with wait, waits.
void submit(const FarmPlan& planAsRead, const std::string& planFile, bool dryRun, bool wait,
            const CommonOptions& common) {
  requirePlanInItsDirectory(planAsRead, planFile);
  requireNoLinksInPlan(planAsRead, planFile);
  const FarmPlan plan = runningThisHairgen(planAsRead, planFile);
  requireUnchangedConfig(plan, planFile);
  const std::vector<bool> done = farm::doneTasks(plan);
  note(common, "farm submit: " + std::to_string(plan.tasks.size()) + " tasks, " +
                   std::to_string(std::count(done.begin(), done.end(), true)) +
                   " already done (outputs carry config " + plan.configDigest + ")");
  const std::unique_ptr<farm::Scheduler> scheduler = farm::slurmScheduler(std::cout, dryRun);
  if (scheduler->submit(plan, done) == 0) {
    note(common, "farm submit: every task is done; nothing to submit");
    return;
  }
  if (!dryRun && wait) scheduler->wait(plan);
}

struct PlanOptions {
  CommonOptions common;
  std::string setup, outDir, frames;
  int shards = 4, chunk = 5, cpus = 4;
};

// What planFarm needs from the command line: this program, absolute paths, the overrides every task
// repeats, the limits.
FarmPlanOptions farmPlanOptions(const PlanOptions& o) {
  FarmPlanOptions options;
  options.hairgen = executablePath();
  options.setup = fs::absolute(o.setup).lexically_normal().string();
  options.directory = fs::absolute(o.outDir).lexically_normal().string();
  if (options.directory.size() > 1 && options.directory.back() == '/') options.directory.pop_back();
  for (const std::string& s : o.common.sets) options.overrides.insert(options.overrides.end(), {"--set", s});
  if (o.common.seed)
    options.overrides.insert(options.overrides.end(), {"--seed", std::to_string(*o.common.seed)});
  options.shards = o.shards;
  options.chunk = o.chunk;
  options.maxCpus = o.cpus;
  options.threads = size_t(tbb::this_task_arena::max_concurrency());
  return options;
}

void registerFarmPlan(CLI::App& farm, int& exitCode) {
  auto planOptions = std::make_shared<PlanOptions>();
  CLI::App* plan = farm.add_subcommand(
      "plan",
      "Write DIR/plan.json: the tasks of `hairgen run` on SETUP (guides and coupe in shards, merged; a shot "
      "simulated, then interpolated, shaded and rendered in chunks of frames), each with its command, "
      "inputs, outputs, dependencies and CPU and memory requests; its outputs equal run's byte for byte");
  plan->add_option("SETUP", planOptions->setup, "The Setup file")->required();
  plan->add_option("-o,--output", planOptions->outDir, "The folder the plan and every task's outputs go to")
      ->required()
      ->type_name("DIR");
  plan->add_option("--frames", planOptions->frames, "A shot's frames (default: Dynamics Frames)")
      ->type_name("A-B");
  plan->add_option("--shards", planOptions->shards,
                   "Shards of grow and interpolate (1 to " + std::to_string(kFarmMaxGroupTasks) + ")")
      ->type_name("N")
      ->capture_default_str();
  plan->add_option("--chunk", planOptions->chunk,
                   "Frames per render task (a shot has at most " + std::to_string(kFarmMaxGroupTasks) +
                       " chunks and " + std::to_string(kFarmMaxFrames) + " frames)")
      ->type_name("FRAMES")
      ->capture_default_str();
  plan->add_option("--cpus", planOptions->cpus,
                   "The most CPUs one task asks for (1 to " + std::to_string(kFarmMaxCpus) + ")")
      ->type_name("N")
      ->capture_default_str()
      ->check(CLI::Range(1, kFarmMaxCpus));
  addCommonFlags(*plan, planOptions->common, true);
  plan->callback([planOptions, &exitCode] {
    PlanOptions& o = *planOptions;
    exitCode = runCommand("farm plan", o.common, [&] {
      Stats stats("farm plan");
      if (!o.frames.empty()) {
        const FrameRange f = parseFrameRange(o.frames, "--frames");
        checkFarmFrames(f, "--frames");
        o.common.sets.push_back("Dynamics.Frames=" + std::to_string(f.first) + " " + std::to_string(f.last));
      }
      Config config = loadStageConfig(o.setup, o.common, SetupUse::kRun, stats);
      if (!o.frames.empty()) requireShotForFrames(config, o.setup);
      Mesh wick = readWick(config);  // as the stages read it: MeshUnits, MeshUpAxis, WickGroup, roots alone
      const FarmPlanOptions options = farmPlanOptions(o);
      const FarmPlan farmPlan = planFarm(config, wick, options);
      createOutputFolder(options.directory);  // never through a link to nothing, nor over a file
      const fs::path file = fs::path(options.directory) / "plan.json";
      writeFileAtomic(file, jsonText(toJson(farmPlan)) + "\n");
      stats.counts()["tasks"] = farmPlan.tasks.size();
      std::cout << file.string() << ": " << farmPlan.tasks.size() << " tasks, config "
                << farmPlan.configDigest << "\n";
      stats.write(o.common);
    });
  });
}

void registerFarmSubmit(CLI::App& farm, int& exitCode) {
  struct SubmitOptions {
    CommonOptions common;
    std::string plan, scheduler;
    bool wait = false, dryRun = false;
  };
  auto submitOptions = std::make_shared<SubmitOptions>();
  CLI::App* submitCmd = farm.add_subcommand(
      "submit",
      "Submit a plan's tasks that are not done (their outputs missing or made with another config) to the "
      "scheduler as job arrays with afterok/aftercorr dependencies, and print the job ids; tasks are "
      "requeueable");
  submitCmd->add_option("PLAN", submitOptions->plan, "DIR/plan.json from `hairgen farm plan`")->required();
  submitCmd->add_option("--scheduler", submitOptions->scheduler, "The scheduler")
      ->type_name("NAME")
      ->required()
      ->check(CLI::IsMember({"slurm"}));
  submitCmd->add_flag(
      "--wait", submitOptions->wait,
      "Return when the plan is done (exit 0) or a task failed (exit 1, naming it and its log)");
  submitCmd->add_flag("--dry-run", submitOptions->dryRun,
                      "Print the sbatch lines as a shell script (each job id in a variable job_NAME); "
                      "submit nothing");
  addCommonFlags(*submitCmd, submitOptions->common, false);
  submitCmd->callback([submitOptions, &exitCode] {
    SubmitOptions& o = *submitOptions;
    exitCode = runCommand("farm submit", o.common, [&] {
      std::error_code ec;
      const uintmax_t bytes = fs::file_size(o.plan, ec);
      if (!ec && bytes > kFarmMaxPlanBytes)
        throw InputError({o.plan, 0}, "is " + std::to_string(bytes) + " bytes; a farm plan is at most " +
                                          std::to_string(kFarmMaxPlanBytes));
      const FarmPlan farmPlan =
          farmPlanFromJson(nlohmann::ordered_json::parse(readFileText(o.plan), nullptr, false), o.plan);
      submit(farmPlan, fs::absolute(o.plan).string(), o.dryRun, o.wait, o.common);
    });
  });
}

}  // namespace

void registerFarm(CLI::App& app, int& exitCode) {
  CLI::App* farm = app.add_subcommand(
      "farm",
      "The work of `hairgen run` as tasks for a render farm: `farm plan` writes them, `farm submit` "
      "hands them to a scheduler (Slurm)");
  farm->require_subcommand(1);
  registerFarmPlan(*farm, exitCode);
  registerFarmSubmit(*farm, exitCode);
}

}  // namespace hairgen::cli
