#include "cli/common.h"

#include <cmath>
#include <cstdio>
#include <iostream>

#include <tbb/global_control.h>
#include <tbb/info.h>

#include "libcore/config/reader.h"
#include "libcore/io/exr_io.h"
#include "libcore/io/hair_cache.h"
#include "libcore/util/error.h"
#include "libcore/util/file_util.h"
#include "libcore/util/json.h"
#include "libcore/util/resources.h"
#include "libcore/util/text.h"

namespace hairgen::cli {

const CLI::Validator kNonNegativeInteger(
    [](std::string& text) -> std::string {
      return parseUInt(text) ? std::string() : "'" + text + "' is not a non-negative integer";
    },
    "UINT");

const CLI::Validator kFiniteNonNegative(
    [](std::string& text) -> std::string {
      std::optional<double> v = parseReal(text);
      return v && std::isfinite(*v) && *v >= 0.0 ? std::string()
                                                 : "'" + text + "' is not a finite number >= 0";
    },
    "FINITE >= 0");

void addCommonFlags(CLI::App& command, CommonOptions& options, bool configFlags) {
  command
      .add_option("--threads", options.threads,
                  "Worker threads, 0 to 4096; 0 uses every core (output is identical for any value)")
      ->type_name("N")
      ->capture_default_str()
      ->check(CLI::Range(0, 4096));
  command.add_flag("--quiet,-q", options.quiet, "Print nothing but errors");
  command
      .add_option("--stats", options.statsFile, "Write timings and counts as JSON to FILE (for farm scripts)")
      ->type_name("FILE.json");
  if (!configFlags) return;
  command.add_flag(
      "--force", options.force,
      "Run work estimated to take more than an hour (work that cannot fit in memory is always refused)");
  command.add_option("--seed", options.seed, "Seed of every random number (overrides Hairstyle.Seed)")
      ->check(kNonNegativeInteger)
      ->type_name("N");
  std::string sections;
  for (const SectionSpec* s : allSections()) sections += (sections.empty() ? "" : ", ") + s->name;
  command
      .add_option("--set", options.sets,
                  "Override a config value without editing files, e.g. --set Hairstyle.HairDensity=160 "
                  "(repeatable; sections " +
                      sections +
                      "; a repeatable key such as Collision.Sphere replaces all its lines; every key: "
                      "hairgen check --keys)")
      ->type_name("Section.Key=VALUE")
      ->take_all()
      ->allow_extra_args(false);
}

std::vector<Override> parseOverrides(const CommonOptions& options) {
  std::vector<Override> overrides;
  for (const std::string& text : options.sets) overrides.push_back(parseOverride(text));
  if (options.seed) overrides.push_back(parseOverride("Hairstyle.Seed=" + std::to_string(*options.seed)));
  return overrides;
}

namespace {
// What the Stats of a failing command had gathered when it was unwound, for runCommand.
nlohmann::ordered_json gFailedStats;
// --stats names a place nothing could be written (its check before the work, or Stats::write, failed):
// the failure does not try it again.
bool gStatsWriteFailed = false;
}  // namespace

Stats::~Stats() {
  if (std::uncaught_exceptions() > exceptions_) {
    json_["seconds"]["total"] =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    gFailedStats = json_;
  }
}

Stats::Stats(std::string command)
    : start_(std::chrono::steady_clock::now()), exceptions_(std::uncaught_exceptions()) {
  json_["command"] = std::move(command);
  json_["version"] = HAIRGEN_VERSION;
  json_["seconds"] = nlohmann::ordered_json::object();
  json_["counts"] = nlohmann::ordered_json::object();
}

void Stats::setOverrides(const std::vector<Override>& overrides) {
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (const Override& o : overrides) list.push_back(o.text);
  json_["overrides"] = list;
}

void Stats::write(const CommonOptions& options) {
  json_["seconds"]["total"] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  nlohmann::ordered_json outputs = nlohmann::ordered_json::array();
  for (const std::filesystem::path& p : committedOutputs()) outputs.push_back(p.string());
  json_["outputs"] = outputs;
  json_["peakMemoryBytes"] = peakResidentBytes();
  json_["exitCode"] = 0;
  if (options.statsFile.empty()) return;
  try {
    writeFileAtomic(options.statsFile, jsonText(json_) + "\n");
  } catch (...) {
    gStatsWriteFailed = true;  // the command fails, and does not try the same place again
    throw;
  }
}

int runCommand(const std::string& command, const CommonOptions& options, const std::function<void()>& body) {
  installInterruptCleanup();
  installMappingGuard();
  forgetCommittedOutputs();
  gFailedStats = nullptr;
  gStatsWriteFailed = false;
  auto failed = [&](const std::string& message, ExitCode code) {
    discardCommittedOutputs();  // a failed command leaves none of its outputs but finished frames
    std::cerr << "hairgen " << command << ": error: " << printableText(oneLine(message)) << "\n";
    if (!options.statsFile.empty() && !gStatsWriteFailed) {
      // A farm script reads why, even from a command that failed before it gathered anything.
      nlohmann::ordered_json stats =
          gFailedStats.is_object() ? gFailedStats : nlohmann::ordered_json::object();
      if (!stats.contains("command")) stats["command"] = command;
      if (!stats.contains("version")) stats["version"] = HAIRGEN_VERSION;
      // What stays: a sequence's finished frames.
      nlohmann::ordered_json kept = nlohmann::ordered_json::array();
      for (const std::filesystem::path& p : committedOutputs()) kept.push_back(p.string());
      stats["outputs"] = kept;
      stats["peakMemoryBytes"] = peakResidentBytes();
      stats["exitCode"] = int(code);
      stats["error"] = oneLine(message);
      try {
        writeFileAtomic(options.statsFile, jsonText(stats) + "\n");
        forgetCommittedOutputs();
      } catch (const std::exception& e) {
        std::cerr << "hairgen " << command << ": error: --stats " << options.statsFile << ": " << e.what()
                  << "\n";
      }
    }
    return static_cast<int>(code);
  };
  // A mapped input's page that could not be read made its arrays zeros (mapped_file.h): whatever that
  // led to, the file's error is the command's.
  auto failedUnlessAMappingFailed = [&](const std::string& message, ExitCode code) {
    try {
      requireMappingsWhole();
    } catch (const Error& e) {
      return failed(e.what(), e.code());
    } catch (...) {  // out of memory while saying so: the command's own error stands
    }
    return failed(message, code);
  };
  try {
    int threads = options.threads > 0 ? options.threads : static_cast<int>(tbb::info::default_concurrency());
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<size_t>(threads));
    setExrThreads(threads);
    if (!options.statsFile.empty()) {  // before the work, as the outputs are
      try {
        requireWritableOutput(options.statsFile);
      } catch (const Error& e) {
        gStatsWriteFailed = true;
        throw Error(e.code(), {}, std::string("--stats: ") + e.what());
      }
    }
    body();
    requireMappingsWhole();  // a page read after the last check
    forgetCommittedOutputs();
    return static_cast<int>(ExitCode::kSuccess);
  } catch (const Error& e) {
    return failedUnlessAMappingFailed(e.what(), e.code());
  } catch (const std::bad_alloc&) {
    return failedUnlessAMappingFailed("out of memory", ExitCode::kWorkFailed);
  } catch (const std::exception& e) {
    return failedUnlessAMappingFailed(std::string("internal: ") + e.what(), ExitCode::kWorkFailed);
  }
}

Config loadStageConfig(const std::filesystem::path& setup, const CommonOptions& options, SetupUse use,
                       Stats& stats) {
  std::vector<Override> overrides = parseOverrides(options);
  stats.setOverrides(overrides);
  Config config = loadConfig(setup, overrides, use);
  stats.json()["configDigest"] = config.digest();
  stats.json()["seed"] = config.hairstyle.seed;
  return config;
}

void addUnitFlags(CLI::App& command, UnitOptions& options, const std::string& file) {
  command
      .add_option("--units", options.units,
                  "The length unit of " + file + " when it is not metres: m, cm, mm, in, or metres per unit")
      ->type_name("UNIT")
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            return parseLengthUnit(text)
                       ? std::string()
                       : "'" + text + "' is not m, cm, mm, in or a number of metres " + "per unit in [" +
                             formatReal(kMinMetresPerUnit) + ", " + formatReal(kMaxMetresPerUnit) + "]";
          },
          "UNIT"));
  command
      .add_option("--up-axis", options.upAxis, "The up axis of " + file + ": z turns z-up to hairgen's +y up")
      ->type_name("y|z")
      ->check(CLI::IsMember({"y", "z"}));
}

UnitConversion unitConversion(const UnitOptions& options) {
  UnitConversion conversion;
  if (!options.units.empty()) conversion.metresPerUnit = parseLengthUnit(options.units);
  if (!options.upAxis.empty()) conversion.upAxis = parseUpAxis(options.upAxis);
  return conversion;
}

Strands readStrandsAs(const std::string& file, const UnitOptions& options) {
  return readStrands(file, unitConversion(options));
}

std::string formatSeconds(double seconds) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f s", seconds);
  return text;
}

void note(const CommonOptions& options, const std::string& line) {
  if (!options.quiet) std::cerr << line << "\n";
}

void warnDropped(const std::string& command, const std::string& file, const WriteReport& report) {
  if (report.droppedStrands == 0) return;
  std::cerr << "hairgen " << command << ": warning: " << file << ": " << report.droppedStrands
            << " strand(s) of fewer than two points (bare follicles) left out: a curve needs two\n";
}

std::string exitCodeHelp() {
  std::string text = "Exit codes:\n";
  for (const ExitCodeInfo& e : kExitCodes)
    text += "  " + std::to_string(int(e.code)) + "  " + e.meaning + "\n";
  return text;
}

std::string HelpFormatter::make_option_opts(const CLI::Option* option) const {
  if (!option->get_option_text().empty()) return " " + option->get_option_text();
  std::string text;
  if (option->get_type_size() != 0) {
    // A positional's name is its label (SETUP, FILE); an option's is its type name, without the
    // validators' descriptions CLI11 appends after a ':'.
    const std::string type = option->get_type_name();
    const std::string label = option->get_positional() ? "" : type.substr(0, type.find(':'));
    if (!label.empty()) text += " " + label;
    if (!option->get_default_str().empty()) text += "=" + option->get_default_str();
    if (option->get_expected_max() == CLI::detail::expected_max_vector_size)
      text += " ...";
    else if (option->get_expected_min() > 1 && label.find(' ') == std::string::npos)  // not "X Y Z"
      text += " x " + std::to_string(option->get_expected());
    if (option->get_required()) text += " REQUIRED";
  }
  if (!option->get_needs().empty()) {
    text += " Needs:";
    for (const CLI::Option* other : option->get_needs()) text += " " + other->get_name();
  }
  if (!option->get_excludes().empty()) {
    text += " Excludes:";
    for (const CLI::Option* other : option->get_excludes()) text += " " + other->get_name();
  }
  return text;
}

void pointAtExitCodes(CLI::App& app) {
  for (CLI::App* command : app.get_subcommands([](const CLI::App*) { return true; })) {
    command->footer("Exit codes: see hairgen --help");
    pointAtExitCodes(*command);
  }
}

void addStandaloneFlag(CLI::App& command, const std::string& name, const std::string& help,
                       std::function<int()> action) {
  command.add_flag_callback(
      name, [action = std::move(action)] { throw CLI::RuntimeError(action()); }, help);
}

void requireShotForFrames(const Config& config, const std::string& setup) {
  if (!config.dynamics.given)
    throw InputError("--frames: " + setup + " names no Dynamics Info; a still has no frames");
}

std::optional<ShardSpec> shardOption(const std::string& shard, const std::string& output, HairFormat format) {
  if (shard.empty()) return std::nullopt;
  const ShardSpec spec = parseShardSpec(shard, "--shard");
  if (format != HairFormat::kHair)
    throw InputError("-o " + output + ": a shard is written as .hair, whose provenance carries its range");
  return spec;
}

}  // namespace hairgen::cli
