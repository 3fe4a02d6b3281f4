// The Slurm back end. Submission: one job array per group of tasks not yet done, each array task
// running its task's command from a script written beside the plan; an array waits for the arrays it
// reads with `afterok` (all their tasks), or `aftercorr` (the task of the same index) where each task
// reads only its counterpart, so chunk k renders as soon as chunk k is shaded. Tasks are submitted
// requeueable. Array task N runs task GROUP.N (0 a group's only task) and logs to logs/ID.log. Plan
// data reaches the scripts and the printed dry run only through farm/shell.h.
#include "farm/slurm.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <map>
#include <ostream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>

#include "farm/done.h"
#include "farm/process.h"
#include "farm/shell.h"
#include "libcore/util/error.h"
#include "libcore/util/file_util.h"
#include "libcore/util/text.h"

namespace hairgen::farm {
namespace {

namespace fs = std::filesystem;

// What runProcess's message adds when a Slurm tool cannot be started.
const char* const kNoSlurm = " (is Slurm installed? scripts/slurm-local.sh start brings up a local one)";
// A Slurm tool that failed: its own message (the last lines of its stderr) and what to do, on one line.
IoError schedulerFailure(const std::string& what, const ProcessResult& r) {
  std::string said = oneLine(r.err);
  while (!said.empty() && said.back() == ' ') said.pop_back();
  constexpr size_t kShown = 400;  // characters of the tool's message a one-line error quotes
  if (said.size() > kShown) said = "..." + said.substr(said.size() - kShown);
  return IoError(what + " failed (exit " + std::to_string(r.status) + ")" +
                 (said.empty() ? "" : ": " + said) +
                 "; if Slurm is down, `scripts/slurm-local.sh start` starts a one-node cluster on this "
                 "machine (`sinfo` shows a cluster's state)");
}

// The shell variable a dry run keeps a submission's job id in: job_NAME, '-' as '_' and '.' as "__"
// (one name for one group or task: names have no "--").
std::string jobVariable(const std::string& name) {
  std::string v = "job_";
  for (char c : name) v += c == '-' ? "_" : c == '.' ? "__" : std::string(1, c);
  return v;
}

// A task's command; its --threads the CPUs Slurm gave the task, which may be fewer than the plan asked
// for on a smaller node (hairgen's outputs are the same whatever --threads is).
std::vector<ShellWord> taskCommand(const FarmTask& task) {
  std::vector<ShellWord> words;
  for (size_t k = 0; k < task.command.size(); ++k) {
    const bool threads = k > 0 && task.command[k - 1] == "--threads";
    words.push_back(threads ? ShellWord{ShellPiece{"SLURM_CPUS_PER_TASK", true, task.command[k]}}
                            : literal(task.command[k]));
  }
  return words;
}

// The plan's tasks by group, in plan order.
struct Group {
  std::string name;
  std::vector<size_t> tasks;  // indices into plan.tasks
};

struct Submission {
  std::string group;
  std::string name;           // the group, or the task of a group submitted task by task
  std::string job;            // the array's job id
  std::vector<size_t> tasks;  // plan.tasks indices submitted
};

// A task's log: logs/ID.log (Slurm's --output names it by the array index, which is the id's number).
fs::path taskLog(const FarmPlan& plan, const FarmTask& task) {
  return fs::path(plan.directory) / "logs" / (task.id + ".log");
}

// One submission of a plan: its groups, the done set, and the arrays submitted so far.
class SlurmSubmitter {
 public:
  SlurmSubmitter(const FarmPlan& plan, const std::vector<bool>& done, std::ostream& out, bool dryRun)
      : plan_(plan), out_(out), dryRun_(dryRun), done_(done) {
    if (done.size() != plan.tasks.size()) throw std::logic_error("a done set for another plan");
    for (size_t i = 0; i < plan.tasks.size(); ++i) {
      const FarmTask& t = plan.tasks[i];
      taskIndex_[t.id] = i;
      auto g =
          std::find_if(groups_.begin(), groups_.end(), [&](const Group& x) { return x.name == t.group; });
      if (g == groups_.end()) g = groups_.insert(groups_.end(), Group{t.group, {}});
      groupOf_.push_back(size_t(g - groups_.begin()));
      g->tasks.push_back(i);
    }
  }

  std::vector<Submission>& submitted() { return submitted_; }

  void submitAll() {
    if (!dryRun_) {
      fs::create_directories(fs::path(plan_.directory) / "slurm");
      fs::create_directories(fs::path(plan_.directory) / "logs");
      readNodes();
    } else {
      out_ << "set -e\n";
    }
    for (size_t g = 0; g < groups_.size(); ++g) submitGroup(g);
  }

 private:
  // The largest node: a request beyond it could never start, so it asks for that node instead.
  void readNodes() {
    const ProcessResult r = runProcess({"sinfo", "--noheader", "--format=%c %m"}, kNoSlurm);
    if (r.status != 0) throw schedulerFailure("sinfo (the cluster's nodes)", r);
    std::istringstream nodes(r.out);
    for (int c = 0; nodes >> c;) {
      uint64_t m = 0;
      nodes >> m;
      if (c > nodeCpus_) nodeMiB_ = m;
      nodeCpus_ = std::max(nodeCpus_, c);
    }
  }

  fs::path script(const Group& g) const { return fs::path(plan_.directory) / "slurm" / (g.name + ".sh"); }

  // The group's script: array task N runs the group's task whose id ends in N (0 for a group of one).
  void writeScript(const Group& g) const {
    std::string text =
        "#!/bin/sh\n# The tasks of one group of a hairgen farm plan, written by `hairgen farm submit`: "
        "array\n"
        "# task N runs task GROUP.N (N 0 for a group of one task, its id the group's name).\n"
        "case \"$SLURM_ARRAY_TASK_ID\" in\n";
    for (size_t i : g.tasks) {
      const FarmTask& t = plan_.tasks[i];
      // The start and end lines time the task apart from the scheduler (scripts/bench.sh farm).
      text += std::to_string(farmArrayIndex(t)) + ")\n  echo " + shellQuote("hairgen-farm: start " + t.id) +
              " \"$(date +%s.%N)\"\n  " + shellLine(taskCommand(t)) + "\n  rc=$?\n  echo " +
              shellQuote("hairgen-farm: end " + t.id) + " \"$(date +%s.%N)\" \"exit $rc\"\n  exit $rc ;;\n";
    }
    text += "esac\necho \"no task $SLURM_ARRAY_TASK_ID in\" " + shellQuote(g.name) + " >&2\nexit 2\n";
    writeFileAtomic(script(g), text.data(), text.size());
    fs::permissions(script(g), fs::perms::owner_exec | fs::perms::group_exec | fs::perms::others_exec,
                    fs::perm_options::add);
  }

  // --output's file name: Slurm replaces %a by the array index (which is the id's number), so each
  // task's log is logs/ID.log; a '%' of the folder is written "%%".
  std::string logPattern(const Group& g) const {
    if (plan_.directory.find('\\') != std::string::npos)
      throw InputError(
          "the plan's directory " + plan_.directory +
          " holds a backslash, which turns off Slurm's --output patterns; plan into another folder");
    std::string dir;
    for (char c : plan_.directory) dir += c == '%' ? std::string("%%") : std::string(1, c);
    const bool single = g.tasks.size() == 1 && farmArrayIndex(plan_.tasks[g.tasks[0]]) == 0;
    return dir + "/logs/" + g.name + (single ? "" : ".%a") + ".log";
  }

  // The job id a dependency names: the real one, or in a dry run the variable the printed line set.
  ShellPiece jobOf(const Submission& s) const {
    return dryRun_ ? ShellPiece{jobVariable(s.name), true, {}} : textPiece(s.job);
  }

  // afterok on every submission this batch reads; aftercorr where each task reads only the task of
  // its own array index in the other.
  ShellWord dependencies(const std::vector<size_t>& batch) const {
    std::set<size_t> from;
    for (size_t i : batch)
      for (const std::string& d : plan_.tasks[i].deps)
        if (!done_[taskIndex_.at(d)]) from.insert(submissionOfTask_.at(taskIndex_.at(d)));
    ShellWord word;
    for (size_t h : from) {
      bool corresponding = submitted_[h].tasks.size() > 1;
      for (size_t i : batch) {
        size_t reads = 0;
        for (const std::string& d : plan_.tasks[i].deps) {
          const size_t j = taskIndex_.at(d);
          if (done_[j] || submissionOfTask_.at(j) != h) continue;
          ++reads;
          corresponding = corresponding && farmArrayIndex(plan_.tasks[j]) == farmArrayIndex(plan_.tasks[i]);
        }
        corresponding = corresponding && reads == 1;
      }
      word.push_back(textPiece(std::string(word.empty() ? "--dependency=" : ",") +
                               (corresponding ? "aftercorr:" : "afterok:")));
      word.push_back(jobOf(submitted_[h]));
    }
    return word;
  }

  std::vector<ShellWord> sbatchLine(const Group& g, const std::vector<size_t>& batch,
                                    const std::string& name) const {
    int cpus = 1;
    uint64_t memory = 1;
    std::string array;
    for (size_t i : batch) {
      array += (array.empty() ? "" : ",") + std::to_string(farmArrayIndex(plan_.tasks[i]));
      cpus = std::max(cpus, plan_.tasks[i].cpus);
      memory = std::max(memory, plan_.tasks[i].memoryMiB);
    }
    if (nodeCpus_ > 0) cpus = std::min(cpus, nodeCpus_);
    if (nodeMiB_ > 0 && memory > nodeMiB_)
      throw InputError(name + " tasks need " + std::to_string(memory) +
                       " MiB, more than the largest node's " + std::to_string(nodeMiB_) + " MiB");
    std::vector<ShellWord> words = {literal("sbatch"),
                                    literal("--parsable"),
                                    literal("--job-name=hairgen-" + name),
                                    literal("--array=" + array),
                                    literal("--cpus-per-task=" + std::to_string(cpus)),
                                    literal("--mem=" + std::to_string(memory) + "M"),
                                    literal("--output=" + logPattern(g)),
                                    literal("--requeue")};
    const ShellWord deps = dependencies(batch);
    if (!deps.empty()) {
      words.push_back(deps);
      words.push_back(literal("--kill-on-invalid-dep=yes"));
    }
    words.push_back(literal(script(g).string()));
    return words;
  }

  void submitGroup(size_t g) {
    const Group& group = groups_[g];
    std::vector<size_t> undone;
    for (size_t i : group.tasks)
      if (!done_[i]) undone.push_back(i);
    if (undone.empty()) return;
    // A group whose tasks wait for one another (the simulation's chunks, each restarting from the last)
    // is submitted task by task; any other as one array.
    bool chained = false;
    for (size_t i : undone)
      for (const std::string& d : plan_.tasks[i].deps) chained = chained || groupOf_[taskIndex_.at(d)] == g;
    std::vector<std::vector<size_t>> batches;
    if (chained)
      for (size_t i : undone) batches.push_back({i});
    else
      batches.push_back(undone);
    if (!dryRun_) writeScript(group);
    for (const std::vector<size_t>& batch : batches) {
      Submission s{group.name, chained ? plan_.tasks[batch.front()].id : group.name, {}, batch};
      const std::vector<ShellWord> line = sbatchLine(group, batch, s.name);
      if (dryRun_) {
        out_ << jobVariable(s.name) << "=$(" << shellLine(line) << ")\n";
      } else {
        std::vector<std::string> argv;
        for (const ShellWord& w : line) argv.push_back(argument(w));
        const ProcessResult r = runProcess(argv, kNoSlurm);
        if (r.status != 0) throw schedulerFailure("sbatch for " + s.name, r);
        s.job = r.out.substr(0, r.out.find_first_of(";\n"));
        out_ << s.name << ": job " << s.job << " (" << s.tasks.size() << " task"
             << (s.tasks.size() == 1 ? "" : "s") << ")\n"
             << std::flush;
      }
      for (size_t i : s.tasks) submissionOfTask_[i] = submitted_.size();
      submitted_.push_back(std::move(s));
    }
  }

  const FarmPlan& plan_;
  std::ostream& out_;
  const bool dryRun_;
  const std::vector<bool> done_;
  std::vector<Group> groups_;
  std::map<std::string, size_t> taskIndex_;  // id → plan index
  std::vector<size_t> groupOf_;
  int nodeCpus_ = 0;
  uint64_t nodeMiB_ = 0;
  std::vector<Submission> submitted_;
  std::map<size_t, size_t> submissionOfTask_;  // plan task → submitted index
};

// Waits until no submitted job is queued or running, cancelling those whose dependency failed; then a
// task that ran without leaving its outputs failed. Throws WorkFailed naming the first and its log.
void waitForJobs(const FarmPlan& plan, const std::vector<Submission>& submitted, std::ostream& out) {
  std::string jobs;
  for (const Submission& s : submitted) jobs += (jobs.empty() ? "" : ",") + s.job;
  for (int failures = 0;;) {
    const ProcessResult r =
        runProcess({"squeue", "--noheader", "--jobs=" + jobs, "--array",
                    "--states=PENDING,RUNNING,COMPLETING,CONFIGURING,SUSPENDED,REQUEUED", "--format=%i %r"},
                   kNoSlurm);
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
        runProcess({"scancel", line.substr(0, space)}, kNoSlurm);
    }
    if (!queued) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
  }
  std::vector<std::string> failed, notRun;
  for (const Submission& s : submitted)
    for (size_t i : s.tasks) {
      const FarmTask& t = plan.tasks[i];
      if (taskDone(t, plan.configDigest)) continue;
      const fs::path log = taskLog(plan, t);
      std::error_code ec;
      (fs::exists(log, ec) ? failed : notRun)
          .push_back(t.id + " (job " + s.job + "_" + std::to_string(farmArrayIndex(t)) + ", log " +
                     log.string() + ")");
    }
  if (failed.empty() && notRun.empty()) {
    out << "farm: the plan is done\n";
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

class SlurmScheduler : public Scheduler {
 public:
  SlurmScheduler(std::ostream& out, bool dryRun) : out_(out), dryRun_(dryRun) {}

  size_t submit(const FarmPlan& plan, const std::vector<bool>& done) override {
    SlurmSubmitter submitter(plan, done, out_, dryRun_);
    submitter.submitAll();
    submitted_ = std::move(submitter.submitted());
    size_t tasks = 0;
    for (const Submission& s : submitted_) tasks += s.tasks.size();
    return tasks;
  }

  void wait(const FarmPlan& plan) override {
    if (dryRun_) throw std::logic_error("a dry run submitted nothing to wait for");
    waitForJobs(plan, submitted_, out_);
  }

 private:
  std::ostream& out_;
  const bool dryRun_;
  std::vector<Submission> submitted_;
};

}  // namespace

std::unique_ptr<Scheduler> slurmScheduler(std::ostream& out, bool dryRun) {
  return std::make_unique<SlurmScheduler>(out, dryRun);
}

}  // namespace hairgen::farm
