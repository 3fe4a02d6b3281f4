// hairgen farm plan SETUP -o DIR | submit PLAN --scheduler slurm [--wait] [--dry-run]: the work of
// `hairgen run` split into tasks (stages/farm_plan.h), and the plan handed to Slurm as job arrays.
//
// Submission (Slurm): one job array per group of tasks not yet done, each array task running its
// task's command from a script written beside the plan; an array waits for the arrays it reads with
// `afterok` (all their tasks), or `aftercorr` (the task of the same index) where each task reads only
// its counterpart, so chunk k renders as soon as chunk k is shaded. A task is done when all its outputs
// exist and carry the plan's config digest (.hair provenance, the EXR header; other files by their
// presence), so submitting a plan again redoes only what is missing or stale. Every output is written
// atomically, so a task killed mid-way leaves nothing that passes for done; tasks are submitted
// requeueable.
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <sstream>
#include <thread>

#include <tbb/task_arena.h>

#include "cli/commands.h"
#include "cli/common.h"
#include "libcore/io/exr_io.h"
#include "libcore/io/hair_cache.h"
#include "libcore/io/hair_io.h"
#include "libcore/io/obj_io.h"
#include "libcore/util/file_util.h"
#include "libcore/util/json.h"
#include "stages/farm_plan.h"

extern char** environ;

namespace hairgen::cli {
namespace {

namespace fs = std::filesystem;

std::string executablePath() {
  std::error_code ec;
  fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw IoError("cannot find the hairgen executable (/proc/self/exe): " + ec.message());
  return exe.string();
}

// Runs argv (found on PATH), its stdout captured, its stderr passed through. Throws IoError when it
// cannot be started.
struct ProcessResult {
  int status = -1;  // exit status, or 128 + signal
  std::string out;
};
ProcessResult runProcess(const std::vector<std::string>& argv) {
  int pipeFds[2];
  if (pipe(pipeFds) != 0) throw IoError("cannot create a pipe to run " + argv[0]);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, pipeFds[1], STDOUT_FILENO);
  posix_spawn_file_actions_addclose(&actions, pipeFds[0]);
  posix_spawn_file_actions_addclose(&actions, pipeFds[1]);
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, argv[0].c_str(), &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  close(pipeFds[1]);
  if (spawned != 0) {
    close(pipeFds[0]);
    throw IoError("cannot run " + argv[0] + ": " + std::strerror(spawned) +
                  (argv[0][0] == 's'
                       ? " (is Slurm installed? scripts/slurm-local.sh start brings up a local one)"
                       : ""));
  }
  ProcessResult result;
  char buffer[4096];
  for (ssize_t n; (n = read(pipeFds[0], buffer, sizeof buffer)) != 0;) {
    if (n < 0) {
      if (errno == EINTR) continue;
      break;
    }
    result.out.append(buffer, size_t(n));
  }
  close(pipeFds[0]);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  result.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return result;
}

std::string shellQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// Whether `file` exists and was made with `digest`: a .hair's provenance, an EXR's
// hairgen:configDigest; any other file by its presence.
bool carriesDigest(const fs::path& file, const std::string& digest) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) return false;
  std::string ext = file.extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  try {
    if (ext == ".hair") return readHairProvenance(file).configDigest == digest;
    if (ext == ".exr") {
      for (const auto& [name, value] : readImageHeader(file).attributes)
        if (name == "hairgen:configDigest") return value == digest;
      return false;
    }
  } catch (const Error&) {
    return false;  // unreadable: a leftover of another run, redone
  }
  return true;
}

bool taskDone(const FarmTask& task, const std::string& digest) {
  for (const std::string& out : task.outputs)
    if (!carriesDigest(out, digest)) return false;
  return true;
}

// The plan's tasks by group, in plan order, and each task's index in its group.
struct Group {
  std::string name;
  std::vector<size_t> tasks;  // indices into plan.tasks
};

struct Submission {
  std::string group;
  std::string name;                // the group, or the task of a group submitted task by task
  std::string job;                 // the array's job id
  std::vector<size_t> tasks;       // plan.tasks indices submitted
  std::vector<size_t> arrayIndex;  // their array indices
};

void waitForJobs(const FarmPlan& plan, const std::vector<Submission>& submitted, const std::string& logs);

// The plan's configuration read again, as its tasks will read it: a Setup, Info file, mesh or shader
// edited since the plan was made gives another digest, and the tasks' outputs would never carry the
// plan's (every task rerun at each submit, --wait reporting tasks that succeeded as failed).
void requireUnchangedConfig(const FarmPlan& plan, const std::string& planFile) {
  CommonOptions asPlanned;
  for (size_t i = 0; i + 1 < plan.overrides.size(); i += 2) {
    if (plan.overrides[i] == "--set") asPlanned.sets.push_back(plan.overrides[i + 1]);
    if (plan.overrides[i] == "--seed") {
      const std::string& seed = plan.overrides[i + 1];
      if (seed.empty() || seed.size() > 19 || seed.find_first_not_of("0123456789") != std::string::npos)
        throw InputError({planFile, 0}, "its --seed '" + seed + "' is not a seed; make the plan again");
      asPlanned.seed = std::stoull(seed);
    }
  }
  const std::string now = loadConfig(plan.setup, parseOverrides(asPlanned), SetupUse::kRun).digest();
  if (now != plan.configDigest)
    throw InputError({planFile, 0},
                     "the Setup or a file it names has changed since this plan was made (config " + now +
                         " now, " + plan.configDigest +
                         " planned); make the plan again with `hairgen farm plan`");
}

void submit(const FarmPlan& plan, const std::string& planFile, bool dryRun, bool wait,
            const CommonOptions& common) {
  requireUnchangedConfig(plan, planFile);
  std::vector<Group> groups;
  std::map<std::string, size_t> taskIndex;  // id → plan index
  std::vector<size_t> groupOf(plan.tasks.size()), indexInGroup(plan.tasks.size());
  for (size_t i = 0; i < plan.tasks.size(); ++i) {
    const FarmTask& t = plan.tasks[i];
    taskIndex[t.id] = i;
    auto g = std::find_if(groups.begin(), groups.end(), [&](const Group& x) { return x.name == t.group; });
    if (g == groups.end()) g = groups.insert(groups.end(), Group{t.group, {}});
    groupOf[i] = size_t(g - groups.begin());
    indexInGroup[i] = g->tasks.size();
    g->tasks.push_back(i);
  }
  std::vector<bool> done(plan.tasks.size());
  size_t skipped = 0;
  for (size_t i = 0; i < plan.tasks.size(); ++i)
    skipped += done[i] = taskDone(plan.tasks[i], plan.configDigest);
  note(common, "farm submit: " + std::to_string(plan.tasks.size()) + " tasks, " + std::to_string(skipped) +
                   " already done (outputs carry config " + plan.configDigest + ")");

  const fs::path dir = plan.directory, scripts = dir / "slurm", logs = dir / "logs";
  if (!dryRun) {
    fs::create_directories(scripts);
    fs::create_directories(logs);
  }
  // A request beyond the largest node could never start: ask for that node instead.
  int nodeCpus = 0;
  uint64_t nodeMiB = 0;
  if (!dryRun) {
    std::istringstream nodes(runProcess({"sinfo", "--noheader", "--format=%c %m"}).out);
    for (int c = 0; nodes >> c;) {
      uint64_t m = 0;
      nodes >> m;
      if (c > nodeCpus) nodeMiB = m;
      nodeCpus = std::max(nodeCpus, c);
    }
  }
  std::vector<Submission> submitted;
  std::map<size_t, size_t> submissionOfTask;  // plan task → submitted index
  for (size_t g = 0; g < groups.size(); ++g) {
    std::vector<size_t> undone;
    for (size_t i : groups[g].tasks)
      if (!done[i]) undone.push_back(i);
    if (undone.empty()) continue;
    // A group whose tasks wait for one another (the simulation's chunks, each restarting from the last)
    // is submitted task by task; any other as one array.
    bool chained = false;
    for (size_t i : undone)
      for (const std::string& d : plan.tasks[i].deps) chained = chained || groupOf[taskIndex.at(d)] == g;
    std::vector<std::vector<size_t>> batches;
    if (chained)
      for (size_t i : undone) batches.push_back({i});
    else
      batches.push_back(undone);
    if (!dryRun) {
      const fs::path script = scripts / (groups[g].name + ".sh");
      std::string text = "#!/bin/sh\n# " + groups[g].name + " tasks of " + planFile +
                         ", written by hairgen farm submit: array task i runs the group's task i.\n"
                         "case \"$SLURM_ARRAY_TASK_ID\" in\n";
      for (size_t i : groups[g].tasks) {
        const FarmTask& t = plan.tasks[i];
        // The start and end lines time the task apart from the scheduler (scripts/bench.sh farm).
        text += std::to_string(indexInGroup[i]) + ")\n  echo \"hairgen-farm: start " + t.id +
                " $(date +%s.%N)\"\n ";
        for (const std::string& arg : t.command) text += " " + shellQuote(arg);
        text +=
            "\n  rc=$?\n  echo \"hairgen-farm: end " + t.id + " $(date +%s.%N) exit $rc\"\n  exit $rc ;;\n";
      }
      text += "esac\necho \"no task $SLURM_ARRAY_TASK_ID in " + groups[g].name + "\" >&2\nexit 2\n";
      writeFileAtomic(script, text.data(), text.size());
      fs::permissions(script, fs::perms::owner_exec | fs::perms::group_exec | fs::perms::others_exec,
                      fs::perm_options::add);
    }
    for (const std::vector<size_t>& batch : batches) {
      Submission s;
      s.group = groups[g].name;
      const std::string name = chained ? plan.tasks[batch.front()].id : s.group;
      s.name = name;
      int cpus = 1;
      uint64_t memory = 1;
      for (size_t i : batch) {
        s.tasks.push_back(i);
        s.arrayIndex.push_back(indexInGroup[i]);
        cpus = std::max(cpus, plan.tasks[i].cpus);
        memory = std::max(memory, plan.tasks[i].memoryMiB);
      }
      if (nodeCpus > 0) cpus = std::min(cpus, nodeCpus);
      if (nodeMiB > 0 && memory > nodeMiB)
        throw InputError(name + " tasks need " + std::to_string(memory) +
                         " MiB, more than the largest node's " + std::to_string(nodeMiB) + " MiB");
      // Dependencies: the submitted jobs this batch's tasks read; aftercorr where each task reads only
      // the task of its own index in another array.
      std::set<size_t> depSubmissions;
      for (size_t i : batch)
        for (const std::string& d : plan.tasks[i].deps)
          if (!done[taskIndex.at(d)]) depSubmissions.insert(submissionOfTask.at(taskIndex.at(d)));
      std::vector<std::string> dependencies;
      for (size_t h : depSubmissions) {
        const Submission& other = submitted[h];
        bool corresponding = other.tasks.size() > 1;
        for (size_t i : batch) {
          size_t reads = 0;
          for (const std::string& d : plan.tasks[i].deps) {
            const size_t j = taskIndex.at(d);
            if (done[j] || submissionOfTask.at(j) != h) continue;
            ++reads;
            corresponding = corresponding && indexInGroup[j] == indexInGroup[i];
          }
          corresponding = corresponding && reads == 1;
        }
        dependencies.push_back((corresponding ? "aftercorr:" : "afterok:") +
                               (dryRun ? "$" + other.name : other.job));
      }
      std::string array;
      for (size_t k : s.arrayIndex) array += (array.empty() ? "" : ",") + std::to_string(k);
      std::vector<std::string> sbatch = {"sbatch",
                                         "--parsable",
                                         "--job-name=hairgen-" + name,
                                         "--array=" + array,
                                         "--cpus-per-task=" + std::to_string(cpus),
                                         "--mem=" + std::to_string(memory) + "M",
                                         "--output=" + (logs / (s.group + ".%a.log")).string(),
                                         "--requeue"};
      if (!dependencies.empty()) {
        std::string dep;
        for (const std::string& d : dependencies) dep += (dep.empty() ? "" : ",") + d;
        sbatch.push_back("--dependency=" + dep);
        sbatch.push_back("--kill-on-invalid-dep=yes");
      }
      sbatch.push_back((scripts / (s.group + ".sh")).string());
      if (dryRun) {
        std::string line = name + "=$(";
        for (size_t k = 0; k < sbatch.size(); ++k) line += (k ? " " : "") + shellQuote(sbatch[k]);
        std::cout << line << ")\n";
      } else {
        const ProcessResult r = runProcess(sbatch);
        if (r.status != 0)
          throw IoError("sbatch for " + name + " failed (exit " + std::to_string(r.status) + ")");
        s.job = r.out.substr(0, r.out.find_first_of(";\n"));
        std::cout << name << ": job " << s.job << " (" << s.tasks.size() << " task"
                  << (s.tasks.size() == 1 ? "" : "s") << ")\n"
                  << std::flush;
      }
      for (size_t i : s.tasks) submissionOfTask[i] = submitted.size();
      submitted.push_back(std::move(s));
    }
  }
  if (submitted.empty()) {
    note(common, "farm submit: every task is done; nothing to submit");
    return;
  }
  if (!dryRun && wait) waitForJobs(plan, submitted, logs.string());
}

// Waits until no submitted job is queued or running, cancelling those whose dependency failed; then a
// task that ran without leaving its outputs failed. Throws WorkFailed naming the first and its log.
void waitForJobs(const FarmPlan& plan, const std::vector<Submission>& submitted, const std::string& logs) {
  std::string jobs;
  for (const Submission& s : submitted) jobs += (jobs.empty() ? "" : ",") + s.job;
  for (int failures = 0;;) {
    const ProcessResult r =
        runProcess({"squeue", "--noheader", "--jobs=" + jobs, "--array",
                    "--states=PENDING,RUNNING,COMPLETING,CONFIGURING,SUSPENDED,REQUEUED", "--format=%i %r"});
    // squeue fails when the controller is busy and when every job has long left it: a few tries tell
    // the two apart.
    if (r.status != 0) {
      if (++failures == 5) break;
      std::this_thread::sleep_for(std::chrono::seconds(1));
      continue;
    }
    failures = 0;
    std::istringstream lines(r.out);
    std::string line;
    bool queued = false;
    while (std::getline(lines, line)) {
      if (line.empty()) continue;
      queued = true;
      const size_t space = line.find(' ');
      if (line.find("DependencyNeverSatisfied") != std::string::npos)
        runProcess({"scancel", line.substr(0, space)});
    }
    if (!queued) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
  }
  std::vector<std::string> failed, notRun;
  for (const Submission& s : submitted)
    for (size_t k = 0; k < s.tasks.size(); ++k) {
      const FarmTask& t = plan.tasks[s.tasks[k]];
      if (taskDone(t, plan.configDigest)) continue;
      const std::string log = logs + "/" + s.group + "." + std::to_string(s.arrayIndex[k]) + ".log";
      std::error_code ec;
      (fs::exists(log, ec) ? failed : notRun)
          .push_back(t.id + " (job " + s.job + "_" + std::to_string(s.arrayIndex[k]) + ", log " + log + ")");
    }
  if (failed.empty() && notRun.empty()) {
    std::cout << "farm: the plan is done\n";
    return;
  }
  std::string message = "the plan did not finish: ";
  if (!failed.empty()) message += "task " + failed.front() + " failed";
  if (failed.size() > 1) message += " (and " + std::to_string(failed.size() - 1) + " more)";
  if (!notRun.empty())
    message += (failed.empty() ? "" : "; ") + std::to_string(notRun.size()) + " task" +
               (notRun.size() == 1 ? "" : "s") + " never ran (" + notRun.front() +
               (notRun.size() > 1 ? ", ..." : "") + ")";
  throw IoError(message + "; submit the plan again to redo only those");
}

}  // namespace

void registerFarm(CLI::App& app, int& exitCode) {
  CLI::App* farm = app.add_subcommand(
      "farm",
      "The work of `hairgen run` as tasks for a render farm: `farm plan` writes them, `farm submit` "
      "hands them to a scheduler (Slurm)");
  farm->require_subcommand(1);
  farm->footer(exitCodeHelp());

  struct PlanOptions {
    CommonOptions common;
    std::string setup, outDir, frames;
    int shards = 4, chunk = 5, cpus = 4;
  };
  auto planOptions = std::make_shared<PlanOptions>();
  CLI::App* plan = farm->add_subcommand(
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
  plan->add_option("--shards", planOptions->shards, "Shards of grow and interpolate")
      ->capture_default_str()
      ->check(CLI::Range(1, 100000));
  plan->add_option("--chunk", planOptions->chunk, "Frames per render task")
      ->capture_default_str()
      ->check(CLI::Range(1, 100000));
  plan->add_option("--cpus", planOptions->cpus, "The most CPUs one task asks for")
      ->capture_default_str()
      ->check(CLI::Range(1, 4096));
  addCommonFlags(*plan, planOptions->common, true);
  plan->footer(exitCodeHelp());
  plan->callback([planOptions, &exitCode] {
    PlanOptions& o = *planOptions;
    exitCode = runCommand("farm plan", o.common, [&] {
      Stats stats("farm plan");
      if (!o.frames.empty()) {
        const FrameRange f = parseFrameRange(o.frames, "--frames");
        o.common.sets.push_back("Dynamics.Frames=" + std::to_string(f.first) + " " + std::to_string(f.last));
      }
      Config config = loadStageConfig(o.setup, o.common, SetupUse::kRun, stats);
      if (!o.frames.empty() && !config.dynamics.given)
        throw InputError("--frames: " + o.setup + " names no Dynamics Info; a still has no frames");
      Mesh wick = readWick(config);  // as the stages read it: MeshUnits, MeshUpAxis, WickGroup, roots alone
      FarmPlanOptions options;
      options.hairgen = executablePath();
      options.setup = fs::absolute(o.setup).lexically_normal().string();
      options.directory = fs::absolute(o.outDir).lexically_normal().string();
      if (options.directory.size() > 1 && options.directory.back() == '/') options.directory.pop_back();
      for (const std::string& s : o.common.sets)
        options.overrides.insert(options.overrides.end(), {"--set", s});
      if (o.common.seed)
        options.overrides.insert(options.overrides.end(), {"--seed", std::to_string(*o.common.seed)});
      options.shards = o.shards;
      options.chunk = o.chunk;
      options.maxCpus = o.cpus;
      options.threads = size_t(tbb::this_task_arena::max_concurrency());
      const FarmPlan farmPlan = planFarm(config, wick, options);
      fs::create_directories(options.directory);
      const fs::path file = fs::path(options.directory) / "plan.json";
      writeFileAtomic(file, jsonText(toJson(farmPlan)) + "\n");
      stats.counts()["tasks"] = farmPlan.tasks.size();
      std::cout << file.string() << ": " << farmPlan.tasks.size() << " tasks, config "
                << farmPlan.configDigest << "\n";
      stats.write(o.common);
    });
  });

  struct SubmitOptions {
    CommonOptions common;
    std::string plan, scheduler;
    bool wait = false, dryRun = false;
  };
  auto submitOptions = std::make_shared<SubmitOptions>();
  CLI::App* submitCmd = farm->add_subcommand(
      "submit",
      "Submit a plan's tasks that are not done (their outputs missing or made with another config) to the "
      "scheduler as job arrays with afterok/aftercorr dependencies, and print the job ids; tasks are "
      "requeueable");
  submitCmd->add_option("PLAN", submitOptions->plan, "DIR/plan.json from `hairgen farm plan`")->required();
  submitCmd->add_option("--scheduler", submitOptions->scheduler, "The scheduler")
      ->required()
      ->check(CLI::IsMember({"slurm"}));
  submitCmd->add_flag(
      "--wait", submitOptions->wait,
      "Return when the plan is done (exit 0) or a task failed (exit 1, naming it and its log)");
  submitCmd->add_flag("--dry-run", submitOptions->dryRun, "Print the sbatch lines; submit nothing");
  addCommonFlags(*submitCmd, submitOptions->common, false);
  submitCmd->footer(exitCodeHelp());
  submitCmd->callback([submitOptions, &exitCode] {
    SubmitOptions& o = *submitOptions;
    exitCode = runCommand("farm submit", o.common, [&] {
      const FarmPlan farmPlan =
          farmPlanFromJson(nlohmann::ordered_json::parse(readFileText(o.plan), nullptr, false), o.plan);
      submit(farmPlan, fs::absolute(o.plan).string(), o.dryRun, o.wait, o.common);
    });
  });
}

}  // namespace hairgen::cli
