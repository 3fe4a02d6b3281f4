// The farm plan as JSON and back, and the rules every plan keeps (farm_plan.h). Apart from planFarm so
// that the fuzz build, which holds only the readers (tests/fuzz), can hold what reads a plan.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <string_view>

#include "farm/plan.h"
#include "libcore/util/error.h"
#include "libcore/util/text.h"

namespace hairgen {
namespace {

// A group's name or a task's id is a job name and a script's and a log's file name: short.
constexpr size_t kMaxNameLength = 64;

using Json = nlohmann::ordered_json;

// `text` as a JSON string: quoted, control characters and invalid UTF-8 escaped or replaced, so a
// message shows what a field holds on one line.
std::string shown(const std::string& text) {
  return Json(text).dump(-1, ' ', false, Json::error_handler_t::replace);
}

bool isLowerOrDigit(char c) {
  return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9');
}

// [a-z][a-z0-9]*(-[a-z0-9]+)*: no "--", so a group's shell variable (job_NAME, '-' as '_', '.' as "__")
// names one group.
bool isGroupName(std::string_view s) {
  if (s.empty() || s.size() > kMaxNameLength || !(s[0] >= 'a' && s[0] <= 'z') || s.back() == '-')
    return false;
  for (size_t i = 0; i < s.size(); ++i)
    if (!isLowerOrDigit(s[i]) && !(s[i] == '-' && s[i - 1] != '-')) return false;
  return true;
}

// N of "GROUP.N" (1..kFarmMaxGroupTasks, no leading zero), 0 for "GROUP", -1 for anything else.
int taskNumber(std::string_view id, std::string_view group) {
  if (id == group) return 0;
  if (id.size() <= group.size() + 1 || id.substr(0, group.size()) != group || id[group.size()] != '.')
    return -1;
  const std::string_view digits = id.substr(group.size() + 1);
  if (digits.size() > 4 || digits[0] == '0') return -1;
  int n = 0;
  for (char c : digits) {
    if (c < '0' || c > '9') return -1;
    n = n * 10 + (c - '0');
  }
  return n <= kFarmMaxGroupTasks ? n : -1;
}

bool isNormalAbsolute(const std::string& path) {
  return path.size() > 1 && path[0] == '/' && path.back() != '/' &&
         std::filesystem::path(path).lexically_normal().string() == path;
}

// The basename of an executable a plan may run: "hairgen", or "hairgen-" / "hairgen." and a suffix of
// letters, digits, '.', '_', '-' (a versioned or sanitizer build).
bool isHairgenName(const std::string& name) {
  if (name == "hairgen") return true;
  if (name.size() < 9 || name.compare(0, 7, "hairgen") != 0 || (name[7] != '-' && name[7] != '.'))
    return false;
  return std::all_of(name.begin() + 8, name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-';
  });
}

// The checks of one plan, each failure an InputError naming the plan file and, where there is one, the
// task.
class PlanRules {
 public:
  PlanRules(const FarmPlan& plan, const std::string& name) : plan_(plan), name_(name) {}

  void check() {
    text(plan_.setup, "its setup");
    text(plan_.directory, "its directory");
    if (!isNormalAbsolute(plan_.setup))
      fail("its setup " + shown(plan_.setup) + " is not an absolute, normal path");
    if (!isNormalAbsolute(plan_.directory))
      fail("its directory " + shown(plan_.directory) + " is not an absolute, normal path (nor \"/\")");
    if (plan_.configDigest.size() < 16 || plan_.configDigest.size() > 64 ||
        plan_.configDigest.find_first_not_of("0123456789abcdef") != std::string::npos)
      fail("its configDigest " + shown(plan_.configDigest) + " is not 16 to 64 hexadecimal digits");
    overrides();
    if (plan_.shards < 1 || plan_.shards > kFarmMaxGroupTasks)
      fail("shards " + std::to_string(plan_.shards) + " is outside 1.." + std::to_string(kFarmMaxGroupTasks));
    if (plan_.chunk < 1 || plan_.chunk > kFarmMaxFrames)
      fail("chunk " + std::to_string(plan_.chunk) + " is outside 1.." + std::to_string(kFarmMaxFrames));
    if (plan_.frames) checkFarmFrames(*plan_.frames, name_ + ": frames");
    if (plan_.tasks.empty()) fail("it has no tasks");
    if (plan_.tasks.size() > kFarmMaxTasks)
      fail("it has " + std::to_string(plan_.tasks.size()) + " tasks; a plan holds at most " +
           std::to_string(kFarmMaxTasks));
    for (const FarmTask& t : plan_.tasks) task(t);
  }

 private:
  [[noreturn]] void fail(const std::string& message) const { throw InputError({name_, 0}, message); }
  [[noreturn]] void fail(const FarmTask& t, const std::string& message) const {
    fail("task " + shown(t.id) + ": " + message);
  }

  void text(const std::string& s, const std::string& what) const {
    if (std::any_of(s.begin(), s.end(), isControl))
      fail(what + " " + shown(s) + " holds a control character (a newline, CR, NUL or the like)");
  }

  void overrides() const {
    if (plan_.overrides.size() % 2) fail("its overrides are not pairs of --set VALUE or --seed N");
    for (size_t i = 0; i < plan_.overrides.size(); i += 2) {
      const std::string &flag = plan_.overrides[i], &value = plan_.overrides[i + 1];
      text(value, "its override");
      if (flag != "--set" && flag != "--seed")
        fail("its override " + shown(flag) + " is not --set or --seed");
      if (flag == "--seed" &&
          (value.empty() || value.size() > 19 || value.find_first_not_of("0123456789") != std::string::npos))
        fail("its --seed " + shown(value) + " is not a seed");
    }
  }

  // Where a file a plan names may be: inside the directory, outside what `farm submit` writes there;
  // an input also the Setup.
  void path(const FarmTask& t, const std::string& p, const char* what, bool mayBeSetup) const {
    if (std::any_of(p.begin(), p.end(), isControl))
      fail(t, std::string(what) + " " + shown(p) +
                  " holds a control character (a newline, CR, NUL or the like)");
    if (mayBeSetup && p == plan_.setup) return;
    const std::string& dir = plan_.directory;
    if (!isNormalAbsolute(p) || !isInsideFolder(p, dir))
      fail(t, std::string(what) + " " + shown(p) +
                  " is not an absolute, normal path inside the plan's directory " + shown(dir) +
                  (mayBeSetup ? " (nor the plan's Setup)" : ""));
    if (p == dir + "/plan.json" || isInsideFolder(p, dir + "/slurm") || isInsideFolder(p, dir + "/logs") ||
        p == dir + "/slurm" || p == dir + "/logs")
      fail(t, std::string(what) + " " + shown(p) +
                  " is the plan file or in slurm/ or logs/, which farm submit writes");
  }

  void task(const FarmTask& t) {
    if (!isGroupName(t.group))
      fail(t, "its group " + shown(t.group) +
                  " is not a name of [a-z0-9] words joined by single '-' (at most " +
                  std::to_string(kMaxNameLength) + " characters)");
    const int number = taskNumber(t.id, t.group);
    if (number < 0)
      fail(t, "its id is neither its group's name " + shown(t.group) + " nor " + t.group +
                  ".N with N in 1.." + std::to_string(kFarmMaxGroupTasks));
    // A group is its one task named as the group, or tasks GROUP.N: array indices 0, or 1..N.
    auto& kind = groupKinds_[t.group];
    if (kind != 0 && (kind == 1) != (number == 0))
      fail(t, "its group " + shown(t.group) + " mixes a task named as the group with tasks GROUP.N");
    if (number == 0 && kind == 1)
      fail(t, "its group " + shown(t.group) + " has two tasks named as the group");
    kind = number == 0 ? 1 : 2;
    if (!ids_.insert(t.id).second) fail(t, "the id appears twice");
    std::set<std::string> deps;
    for (const std::string& d : t.deps) {
      if (!deps.insert(d).second) fail(t, "it depends on " + shown(d) + " twice");
      if (d == t.id || !ids_.count(d))
        fail(t, "it depends on " + shown(d) + ", which is not a task before it");
    }
    if (t.cpus < 1 || t.cpus > kFarmMaxCpus)
      fail(t, "cpus " + std::to_string(t.cpus) + " is outside 1.." + std::to_string(kFarmMaxCpus));
    if (t.memoryMiB < 1 || t.memoryMiB > kFarmMaxMemoryMiB)
      fail(t, "memoryMiB " + std::to_string(t.memoryMiB) + " is outside 1.." +
                  std::to_string(kFarmMaxMemoryMiB));
    if (!std::isfinite(t.estimatedSeconds) || t.estimatedSeconds < 0)
      fail(t, "estimatedSeconds is not a finite number of seconds, 0 or more");
    if (t.outputs.empty()) fail(t, "it has no outputs");
    for (const std::string& o : t.outputs) path(t, o, "output", false);
    for (const std::string& i : t.inputs) path(t, i, "input", true);
    command(t);
  }

  // argv[0] a hairgen executable, argv[1] a stage, then the stage's paths and options.
  void command(const FarmTask& t) const {
    const std::vector<std::string>& argv = t.command;
    if (argv.size() < 2) fail(t, "its command is not a hairgen executable and a stage");
    text(argv[0], "task " + shown(t.id) + ": its executable");
    if (!isNormalAbsolute(argv[0]) || !isHairgenName(std::filesystem::path(argv[0]).filename().string()))
      fail(t, "its executable " + shown(argv[0]) + " is not a hairgen executable by its absolute path");
    static const std::set<std::string> stages = {"grow",     "interpolate", "shade", "render",
                                                 "simulate", "merge",       "movie"};
    if (!stages.count(argv[1])) fail(t, "its stage " + shown(argv[1]) + " is not one a plan runs");
    static const std::set<std::string> pathOptions = {"-o",     "--guides",  "--hair",
                                                      "--rest", "--preview", "--gif"};
    static const std::set<std::string> valueOptions = {"--shard", "--frames", "--fps",
                                                       "--set",   "--seed",   "--threads"};
    for (size_t k = 2; k < argv.size(); ++k) {
      const std::string& a = argv[k];
      if (a == "--quiet") continue;
      if (!a.empty() && a[0] == '-') {
        if (!pathOptions.count(a) && !valueOptions.count(a))
          fail(t, "its command's option " + shown(a) + " is not one a plan uses");
        if (++k == argv.size()) fail(t, "its command's " + a + " has no value");
        if (pathOptions.count(a)) {
          path(t, argv[k], "command path", false);
        } else {
          text(argv[k], "task " + shown(t.id) + ": its command's " + a);
          if (a == "--threads") threads(t, argv[k]);
        }
        continue;
      }
      path(t, a, "command path", true);
    }
  }

  void threads(const FarmTask& t, const std::string& value) const {
    const bool digits = !value.empty() && value.size() <= 4 && value[0] != '0' &&
                        value.find_first_not_of("0123456789") == std::string::npos;
    if (!digits || std::stoi(value) > kFarmMaxCpus)
      fail(t, "its command's --threads " + shown(value) + " is not a count of 1.." +
                  std::to_string(kFarmMaxCpus));
  }

  const FarmPlan& plan_;
  const std::string& name_;
  std::set<std::string> ids_;
  std::map<std::string, int> groupKinds_;  // 1: one task named as the group; 2: tasks GROUP.N
};

// JSON values read with their type and range checked, so that no conversion is out of range.
int64_t integer(const Json& j, const char* key, int64_t low, int64_t high, const FileLoc& where) {
  const Json& v = j.at(key);
  std::optional<int64_t> value;
  if (v.is_number_unsigned() && v.get<uint64_t>() <= uint64_t(high))
    value = int64_t(v.get<uint64_t>());
  else if (v.is_number_integer() && !v.is_number_unsigned())
    value = v.get<int64_t>();
  if (!value || *value < low || *value > high)
    throw InputError(where, std::string("\"") + key + "\" is " +
                                v.dump(-1, ' ', false, Json::error_handler_t::replace) +
                                ", not an integer in " + std::to_string(low) + ".." + std::to_string(high));
  return *value;
}

FarmTask taskFromJson(const Json& tj, const FileLoc& where) {
  FarmTask t;
  t.id = tj.at("id").get<std::string>();
  t.group = tj.at("group").get<std::string>();
  t.command = tj.at("command").get<std::vector<std::string>>();
  t.inputs = tj.at("inputs").get<std::vector<std::string>>();
  t.outputs = tj.at("outputs").get<std::vector<std::string>>();
  t.deps = tj.at("deps").get<std::vector<std::string>>();
  const FileLoc at{where.file + ": task " + shown(t.id), 0};
  t.cpus = int(integer(tj, "cpus", 1, kFarmMaxCpus, at));
  t.memoryMiB = uint64_t(integer(tj, "memoryMiB", 1, int64_t(kFarmMaxMemoryMiB), at));
  if (!tj.at("estimatedSeconds").is_number()) throw InputError(at, "\"estimatedSeconds\" is not a number");
  t.estimatedSeconds = tj["estimatedSeconds"].get<double>();
  return t;
}

}  // namespace

void checkFarmFrames(const FrameRange& frames, const std::string& what) {
  const int64_t count = int64_t(frames.last) - int64_t(frames.first) + 1;
  const std::string range = std::to_string(frames.first) + "-" + std::to_string(frames.last);
  if (count < 1) throw InputError(what + " " + range + ": the last frame comes before the first");
  if (count > kFarmMaxFrames)
    throw InputError(what + " " + range + ": " + std::to_string(count) +
                     " frames; a farm plan holds at most " + std::to_string(kFarmMaxFrames) +
                     " (plan the shot in parts)");
}

bool isInsideFolder(const std::string& path, const std::string& dir) {
  return path.size() > dir.size() + 1 && path.compare(0, dir.size(), dir) == 0 && path[dir.size()] == '/';
}

void validateFarmPlan(const FarmPlan& plan, const std::string& name) {
  PlanRules(plan, name).check();
}

int farmArrayIndex(const FarmTask& task) {
  return std::max(taskNumber(task.id, task.group), 0);
}

Json toJson(const FarmPlan& plan) {
  Json tasks = Json::array();
  for (const FarmTask& t : plan.tasks)
    tasks.push_back({{"id", t.id},
                     {"group", t.group},
                     {"command", t.command},
                     {"inputs", t.inputs},
                     {"outputs", t.outputs},
                     {"deps", t.deps},
                     {"cpus", t.cpus},
                     {"memoryMiB", t.memoryMiB},
                     {"estimatedSeconds", t.estimatedSeconds}});
  Json frames = nullptr;
  if (plan.frames) frames = {{"first", plan.frames->first}, {"last", plan.frames->last}};
  return {{"format", "hairgen-farm-plan"},
          {"version", 1},
          {"setup", plan.setup},
          {"directory", plan.directory},
          {"configDigest", plan.configDigest},
          {"overrides", plan.overrides},
          {"shards", plan.shards},
          {"chunk", plan.chunk},
          {"frames", frames},
          {"tasks", tasks}};
}

FarmPlan farmPlanFromJson(const Json& j, const std::string& name) {
  const FileLoc where{name, 0};
  FarmPlan plan;
  std::string field;  // what is being read, for a message
  try {
    if (!j.is_object() || !j.contains("format") || j["format"] != "hairgen-farm-plan")
      throw InputError(where, "is not a hairgen farm plan (no \"format\": \"hairgen-farm-plan\")");
    if (!j.contains("version") || j["version"] != 1)
      throw InputError(where,
                       "is a farm plan of version " +
                           j.value("version", Json()).dump(-1, ' ', false, Json::error_handler_t::replace) +
                           "; this hairgen reads version 1");
    field = "setup";
    plan.setup = j.at("setup").get<std::string>();
    field = "directory";
    plan.directory = j.at("directory").get<std::string>();
    field = "configDigest";
    plan.configDigest = j.at("configDigest").get<std::string>();
    field = "overrides";
    plan.overrides = j.at("overrides").get<std::vector<std::string>>();
    field = "shards";
    plan.shards = int(integer(j, "shards", 1, kFarmMaxGroupTasks, where));
    field = "chunk";
    plan.chunk = int(integer(j, "chunk", 1, kFarmMaxFrames, where));
    field = "frames";
    if (!j.at("frames").is_null()) {
      const Json& f = j["frames"];
      if (!f.is_object())
        throw InputError(where, "\"frames\" is neither null nor {\"first\": A, \"last\": B}");
      plan.frames = FrameRange{int(integer(f, "first", INT32_MIN, INT32_MAX, where)),
                               int(integer(f, "last", INT32_MIN, INT32_MAX, where))};
    }
    field = "tasks";
    const Json& tasks = j.at("tasks");
    if (!tasks.is_array()) throw InputError(where, "\"tasks\" is not an array");
    if (tasks.size() > kFarmMaxTasks)
      throw InputError(where, "it has " + std::to_string(tasks.size()) + " tasks; a plan holds at most " +
                                  std::to_string(kFarmMaxTasks));
    for (const Json& tj : tasks) {
      field = "tasks[" + std::to_string(plan.tasks.size()) + "]";
      plan.tasks.push_back(taskFromJson(tj, where));
    }
  } catch (const nlohmann::json::exception& e) {
    throw InputError(where, "is not a valid farm plan: " +
                                (field.empty() ? std::string() : "\"" + field + "\": ") + e.what());
  }
  validateFarmPlan(plan, name);
  return plan;
}

}  // namespace hairgen
