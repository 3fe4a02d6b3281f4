// What every hairgen command shares: the common flags, --stats, and the one place errors become
// exit codes.
#pragma once

#include <chrono>
#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "libcore/config/params.h"
#include "libcore/config/setup.h"
#include "libcore/io/hair_cache.h"
#include "libcore/model/mesh.h"
#include "libcore/model/shards.h"
#include "libcore/model/strands.h"
#include "libcore/model/units.h"
#include "libcore/util/error.h"
#include "libcore/util/stopwatch.h"

namespace hairgen::cli {

struct CommonOptions {
  int threads = 0;                // 0 = every core
  std::optional<uint64_t> seed;   // overrides Hairstyle.Seed
  std::vector<std::string> sets;  // --set Section.Key=VALUE, as given
  bool quiet = false;
  bool force = false;     // run work estimated to take absurdly long
  std::string statsFile;  // --stats FILE.json
};

// Validators for numbers on the command line, as strict as the config reader: no sign wrapping into an
// unsigned integer, no NaN or infinity passing a range check.
extern const CLI::Validator kNonNegativeInteger;
extern const CLI::Validator kFiniteNonNegative;

// Registers --threads, --quiet and --stats; with `configFlags` also --seed and --set.
void addCommonFlags(CLI::App& command, CommonOptions& options, bool configFlags);

// Parses the --set arguments (and --seed) into overrides. Throws InputError.
std::vector<Override> parseOverrides(const CommonOptions& options);

// Collects timings and counts for --stats.
// Every file has the same keys, in camelCase: command, version, configDigest and seed (commands that read
// a Setup), overrides, seconds, counts, outputs (the files written), peakMemoryBytes, exitCode, and on
// failure error. A command that fails still writes its --stats file, with what it had gathered.
class Stats {
 public:
  explicit Stats(std::string command);
  ~Stats();  // while a command fails, hands what it gathered to runCommand's --stats file
  Stats(const Stats&) = delete;
  Stats& operator=(const Stats&) = delete;
  void time(const std::string& phase, double seconds) { json_["seconds"][phase] = seconds; }
  // Adds to a phase's time (a phase done in several pieces).
  void add(const std::string& phase, double seconds) {
    time(phase, json_["seconds"].value(phase, 0.0) + seconds);
  }
  nlohmann::ordered_json& counts() { return json_["counts"]; }
  nlohmann::ordered_json& json() { return json_; }
  void setOverrides(const std::vector<Override>& overrides);
  // Adds the total time and writes the file (atomically) if one was asked for.
  void write(const CommonOptions& options);

 private:
  std::chrono::steady_clock::time_point start_;
  nlohmann::ordered_json json_;
  int exceptions_ = 0;  // std::uncaught_exceptions() when made
};

// --units and --up-axis: the lengths and up axis of a strand file made elsewhere (PLY, .data, a cyHair
// file), converted to metres, +y up on reading (UnitConversion in libcore/model/units.h).
struct UnitOptions {
  std::string units;   // m, cm, mm, in or metres per unit; "" leaves the file's own
  std::string upAxis;  // y or z; "" leaves the file's own
};
// Registers both on `command`, saying they apply to `file` ("the guides").
void addUnitFlags(CLI::App& command, UnitOptions& options, const std::string& file);
UnitConversion unitConversion(const UnitOptions& options);
// Reads strands (readStrands) and applies the options' conversion, recorded in their provenance.
Strands readStrandsAs(const std::string& file, const UnitOptions& options);

// The meshes of a job, read as the Setup says (MeshUnits, MeshUpAxis, WickGroup) so that they are in
// metres, +y up, with the `auto` collision shapes fitted to them.
struct Scene {
  std::optional<Mesh> wick;  // when the command needs it and the Setup names one
  std::optional<Mesh> head;  // when the command needs it, or a shape is fitted to it
};
Mesh readWick(const Config& config);
Mesh readHead(const Config& config);
// Reads the meshes, fits `config.collision`'s auto shapes, and judges the scene (checkScene, and
// with `estimates` the work of every stage of `hairgen run`): a refusal is an InputError (exit 2)
// unless --force, a memory refusal always; warnings go to stderr. Records the meshes' conversion in
// `stats`.
Scene readScene(const CommonOptions& options, Config& config, bool needWick, bool needHead, Stats& stats);

// "1.23 s"
std::string formatSeconds(double seconds);

// Parses --set and --seed, records them in `stats`, and reads the Setup for `use`.
Config loadStageConfig(const std::filesystem::path& setup, const CommonOptions& options, SetupUse use,
                       Stats& stats);

// Runs one command body with the thread limit applied, catching every error once: prints
// "hairgen CMD: error: FILE:LINE: message" and returns the documented exit code.
int runCommand(const std::string& command, const CommonOptions& options, const std::function<void()>& body);

// Progress and notes on stderr unless --quiet.
void note(const CommonOptions& options, const std::string& line);

// "hairgen CMD: warning: FILE: N strand(s) of fewer than two points (bare follicles) left out: ..." on
// stderr, even with
// --quiet (what a file does not hold), when the format dropped any.
void warnDropped(const std::string& command, const std::string& file, const WriteReport& report);

// The exit-code table shown in `hairgen --help`; every command's help points there in one line.
std::string exitCodeHelp();

// Help as a user reads it: an option's label is its type name alone (N, SECONDS, FILE), never CLI11's
// validators' descriptions (`INT:INT in [0 - 4096]`); an option's range is said in its text. Set on
// the top-level app before the commands are registered, which take it.
class HelpFormatter : public CLI::Formatter {
 public:
  std::string make_option_opts(const CLI::Option* option) const override;
};

// Gives every command and subcommand of `app` the one-line footer that points at the exit codes.
void pointAtExitCodes(CLI::App& app);

// A flag that does a whole job by itself and needs none of the command's required arguments (render
// --list-devices, check --keys): `action` runs when the command line has been read, before the
// requirements are checked, and the program ends with the exit code it returns (main catches the
// CLI::RuntimeError that carries it). Register it after the common flags, so that they are read first.
void addStandaloneFlag(CLI::App& command, const std::string& name, const std::string& help,
                       std::function<int()> action);

// --frames A-B of run and farm plan on a still: an InputError, as a still has no frames.
void requireShotForFrames(const Config& config, const std::string& setup);

// --shard K/N of grow and interpolate: none when not given; a shard is written as .hair (its provenance
// carries the range), so another output format is an InputError.
std::optional<ShardSpec> shardOption(const std::string& shard, const std::string& output, HairFormat format);

}  // namespace hairgen::cli
