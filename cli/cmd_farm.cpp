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
// requeueable. Array task N runs task GROUP.N (0 a group's only task) and logs to logs/ID.log.
//
// A plan is input: farmPlanFromJson checks it by validateFarmPlan's rules, and its data reaches the
// scripts and the printed dry run only through shellQuote (one word, single-quoted; no control
// character) and shellWord (a job id's or SLURM_CPUS_PER_TASK's variable, double-quoted).
#include <poll.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
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
#include "libcore/util/text.h"
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

// Runs argv (found on PATH) with its stdout and stderr captured. Throws IoError when it cannot be
// started.
struct ProcessResult {
  int status = -1;  // exit status, or 128 + signal
  std::string out, err;
};

// Reads both pipes until both close: a child that fills one while the other is read never blocks.
void drainPipes(int outFd, int errFd, ProcessResult& result) {
  // What of a tool's stderr is kept: its last lines are what a message quotes.
  constexpr size_t kMaxErrBytes = 64 << 10;
  pollfd fds[2] = {{outFd, POLLIN, 0}, {errFd, POLLIN, 0}};
  std::string* into[2] = {&result.out, &result.err};
  for (int open = 2; open > 0;) {
    if (poll(fds, 2, -1) < 0) {
      if (errno == EINTR) continue;
      break;
    }
    for (int k = 0; k < 2; ++k) {
      if (fds[k].fd < 0 || !(fds[k].revents & (POLLIN | POLLHUP | POLLERR))) continue;
      char buffer[4096];
      const ssize_t n = read(fds[k].fd, buffer, sizeof buffer);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        fds[k].fd = -1;
        --open;
        continue;
      }
      into[k]->append(buffer, size_t(n));
      if (k == 1 && result.err.size() > kMaxErrBytes) result.err.erase(0, result.err.size() - kMaxErrBytes);
    }
  }
}

ProcessResult runProcess(const std::vector<std::string>& argv) {
  int outPipe[2], errPipe[2];
  if (pipe(outPipe) != 0) throw IoError("cannot create a pipe to run " + argv[0]);
  if (pipe(errPipe) != 0) {
    close(outPipe[0]);
    close(outPipe[1]);
    throw IoError("cannot create a pipe to run " + argv[0]);
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, outPipe[1], STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, errPipe[1], STDERR_FILENO);
  for (int fd : {outPipe[0], outPipe[1], errPipe[0], errPipe[1]})
    posix_spawn_file_actions_addclose(&actions, fd);
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, argv[0].c_str(), &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  close(outPipe[1]);
  close(errPipe[1]);
  if (spawned != 0) {
    close(outPipe[0]);
    close(errPipe[0]);
    throw IoError("cannot run " + argv[0] + ": " + std::strerror(spawned) +
                  " (is Slurm installed? scripts/slurm-local.sh start brings up a local one)");
  }
  ProcessResult result;
  drainPipes(outPipe[0], errPipe[0], result);
  close(outPipe[0]);
  close(errPipe[0]);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  result.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return result;
}

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

// ---- Shell text. Every byte of plan data that reaches a shell passes through shellQuote, and every
// shell variable through shellWord; nothing else writes shell.

// A piece of one shell word: literal text, or a shell variable's value ("${name}", or
// "${name:-fallback}" where fallback is a count).
struct ShellPiece {
  std::string text;  // the literal text, or the variable's name
  bool variable = false;
  std::string fallback;
};
using ShellWord = std::vector<ShellPiece>;

ShellPiece textPiece(std::string text) {
  return ShellPiece{std::move(text), false, {}};
}
ShellWord literal(std::string text) {
  return {textPiece(std::move(text))};
}

// `s` single-quoted: the shell reads every byte as itself. A control character (which a valid plan
// never holds) is refused rather than quoted, so no line of a script is ever split.
std::string shellQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
      throw InputError("a control character in '" + oneLine(s) + "' cannot go into a shell script");
    out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  }
  return out + "'";
}

bool isShellName(const std::string& s) {
  return !s.empty() && !std::isdigit(static_cast<unsigned char>(s[0])) &&
         std::all_of(s.begin(), s.end(),
                     [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}

// One word: literal pieces single-quoted, variables double-quoted, side by side.
std::string shellWord(const ShellWord& word) {
  std::string out;
  for (const ShellPiece& p : word) {
    if (!p.variable) {
      out += shellQuote(p.text);
      continue;
    }
    if (!isShellName(p.text) || p.fallback.find_first_not_of("0123456789") != std::string::npos)
      throw std::logic_error("not a shell variable: " + p.text + " " + p.fallback);
    out += "\"${" + p.text + (p.fallback.empty() ? "" : ":-" + p.fallback) + "}\"";
  }
  return out.empty() ? "''" : out;
}

std::string shellLine(const std::vector<ShellWord>& words) {
  std::string line;
  for (const ShellWord& w : words) line += (line.empty() ? "" : " ") + shellWord(w);
  return line;
}

// The word as a program's argument, every piece literal (a real submission knows its job ids).
std::string argument(const ShellWord& word) {
  std::string out;
  for (const ShellPiece& p : word) {
    if (p.variable) throw std::logic_error("an unset shell variable in an argument: " + p.text);
    out += p.text;
  }
  return out;
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

// ---- The plan's state and its groups.

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

void waitForJobs(const FarmPlan& plan, const std::vector<Submission>& submitted);

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

class SlurmSubmitter {
 public:
  SlurmSubmitter(const FarmPlan& plan, bool dryRun) : plan_(plan), dryRun_(dryRun) {
    for (size_t i = 0; i < plan.tasks.size(); ++i) {
      const FarmTask& t = plan.tasks[i];
      taskIndex_[t.id] = i;
      auto g =
          std::find_if(groups_.begin(), groups_.end(), [&](const Group& x) { return x.name == t.group; });
      if (g == groups_.end()) g = groups_.insert(groups_.end(), Group{t.group, {}});
      groupOf_.push_back(size_t(g - groups_.begin()));
      g->tasks.push_back(i);
      done_.push_back(taskDone(t, plan.configDigest));
    }
  }

  size_t doneCount() const { return size_t(std::count(done_.begin(), done_.end(), true)); }
  const std::vector<Submission>& submitted() const { return submitted_; }

  void submitAll() {
    if (!dryRun_) {
      fs::create_directories(fs::path(plan_.directory) / "slurm");
      fs::create_directories(fs::path(plan_.directory) / "logs");
      readNodes();
    } else {
      std::cout << "set -e\n";
    }
    for (size_t g = 0; g < groups_.size(); ++g) submitGroup(g);
  }

 private:
  // The largest node: a request beyond it could never start, so it asks for that node instead.
  void readNodes() {
    const ProcessResult r = runProcess({"sinfo", "--noheader", "--format=%c %m"});
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
        std::cout << jobVariable(s.name) << "=$(" << shellLine(line) << ")\n";
      } else {
        std::vector<std::string> argv;
        for (const ShellWord& w : line) argv.push_back(argument(w));
        const ProcessResult r = runProcess(argv);
        if (r.status != 0) throw schedulerFailure("sbatch for " + s.name, r);
        s.job = r.out.substr(0, r.out.find_first_of(";\n"));
        std::cout << s.name << ": job " << s.job << " (" << s.tasks.size() << " task"
                  << (s.tasks.size() == 1 ? "" : "s") << ")\n"
                  << std::flush;
      }
      for (size_t i : s.tasks) submissionOfTask_[i] = submitted_.size();
      submitted_.push_back(std::move(s));
    }
  }

  const FarmPlan& plan_;
  const bool dryRun_;
  std::vector<Group> groups_;
  std::map<std::string, size_t> taskIndex_;  // id → plan index
  std::vector<size_t> groupOf_;
  std::vector<bool> done_;
  int nodeCpus_ = 0;
  uint64_t nodeMiB_ = 0;
  std::vector<Submission> submitted_;
  std::map<size_t, size_t> submissionOfTask_;  // plan task → submitted index
};

void submit(const FarmPlan& plan, const std::string& planFile, bool dryRun, bool wait,
            const CommonOptions& common) {
  requirePlanInItsDirectory(plan, planFile);
  requireUnchangedConfig(plan, planFile);
  SlurmSubmitter slurm(plan, dryRun);
  note(common, "farm submit: " + std::to_string(plan.tasks.size()) + " tasks, " +
                   std::to_string(slurm.doneCount()) + " already done (outputs carry config " +
                   plan.configDigest + ")");
  slurm.submitAll();
  if (slurm.submitted().empty()) {
    note(common, "farm submit: every task is done; nothing to submit");
    return;
  }
  if (!dryRun && wait) waitForJobs(plan, slurm.submitted());
}

// Waits until no submitted job is queued or running, cancelling those whose dependency failed; then a
// task that ran without leaving its outputs failed. Throws WorkFailed naming the first and its log.
void waitForJobs(const FarmPlan& plan, const std::vector<Submission>& submitted) {
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

}  // namespace hairgen::cli
