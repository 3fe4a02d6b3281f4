#include "libcore/io/movie.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <vector>

#include "libcore/util/error.h"
#include "libcore/util/file_util.h"
#include "libcore/util/text.h"

extern char** environ;

namespace hairgen {
namespace {

namespace fs = std::filesystem;

// ffmpeg on the PATH, or "".
std::string findFfmpeg() {
  const char* path = std::getenv("PATH");
  std::string dirs = path ? path : "/usr/bin:/bin";
  size_t start = 0;
  while (start <= dirs.size()) {
    size_t end = dirs.find(':', start);
    if (end == std::string::npos) end = dirs.size();
    const fs::path candidate = fs::path(dirs.substr(start, end - start)) / "ffmpeg";
    if (::access(candidate.c_str(), X_OK) == 0) return candidate.string();
    start = end + 1;
  }
  return {};
}

// Runs `argv` (argv[0] the program), its output into `log`; returns its exit status.
int runProgram(const std::vector<std::string>& argv, const fs::path& log) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, args[0], &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) return -1;
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// The last line ffmpeg wrote, for the error message.
std::string lastLine(const fs::path& log) {
  std::ifstream in(log);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return last;
}

}  // namespace

bool writeMovie(const fs::path& pngPattern, const FrameRange& frames, const fs::path& mp4,
                const fs::path& gif, const MovieOptions& options) {
  const std::string ffmpeg = findFfmpeg();
  if (ffmpeg.empty()) return false;
  // ffmpeg numbers its input files printf-style.
  std::string name = pngPattern.filename().string();
  const size_t hash = name.find('#');
  size_t run = hash;
  while (hash != std::string::npos && run < name.size() && name[run] == '#') ++run;
  const std::string input =
      hash == std::string::npos  // already %04d
          ? pngPattern.string()
          : (pngPattern.parent_path() /
             (name.substr(0, hash) + "%0" + std::to_string(run - hash) + "d" + name.substr(run)))
                .string();
  const std::vector<std::string> common = {ffmpeg,
                                           "-nostdin",
                                           "-y",
                                           "-loglevel",
                                           "error",
                                           "-framerate",
                                           formatReal(options.frameRate),
                                           "-start_number",
                                           std::to_string(frames.first),
                                           "-i",
                                           input,
                                           "-frames:v",
                                           std::to_string(frames.count())};
  auto encode = [&](const fs::path& target, std::vector<std::string> tail) {
    if (target.empty()) return;
    writeThroughTemporary(target, [&](const fs::path& temporary) {
      std::vector<std::string> argv = common;
      argv.insert(argv.end(), tail.begin(), tail.end());
      argv.push_back(temporary.string());
      const fs::path log = fs::path(temporary.string() + ".log");
      const int status = runProgram(argv, log);
      const std::string why = lastLine(log);
      std::error_code ignored;
      fs::remove(log, ignored);
      if (status != 0)
        throw IoError({target.string(), 0},
                      "ffmpeg failed (" + std::to_string(status) + "): " + oneLine(why));
    });
  };
  encode(mp4,
         {"-c:v", "libx264", "-pix_fmt", "yuv420p", "-crf", "18", "-movflags", "+faststart", "-f", "mp4"});
  const std::string filter =
      "fps=" + formatReal(options.gifFrameRate) + ",scale=" + std::to_string(options.gifWidth) +
      ":-1:flags=lanczos,split[a][b];[a]palettegen=stats_mode=diff[p];[b][p]paletteuse";
  encode(gif, {"-vf", filter, "-loop", "0", "-f", "gif"});
  return true;
}

}  // namespace hairgen
