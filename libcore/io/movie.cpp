#include "libcore/io/movie.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstring>
#include <exception>
#include <sstream>
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
    std::error_code ec;
    if (fs::is_regular_file(candidate, ec) && ::access(candidate.c_str(), X_OK) == 0)
      return candidate.string();
    start = end + 1;
  }
  return {};
}

// An anonymous file for ffmpeg's messages: no name anyone could have put a link at, gone when closed.
int anonymousLog() {
  const fs::path dir = fs::temp_directory_path();
  int fd = ::open(dir.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
  if (fd >= 0) return fd;
  std::string name = (dir / "hairgen-ffmpeg-XXXXXX").string();
  fd = ::mkostemp(name.data(), O_CLOEXEC);
  if (fd >= 0) ::unlink(name.c_str());
  return fd;
}

// The last line of text in `fd` (ffmpeg's last error), read from its start.
std::string lastLine(int fd) {
  std::string text, line, last;
  char chunk[4096];
  for (off_t at = 0;;) {
    const ssize_t n = ::pread(fd, chunk, sizeof chunk, at);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    text.append(chunk, size_t(n));
    at += n;
    if (text.size() > (1u << 20)) text.erase(0, text.size() - (1u << 16));  // the end is what matters
  }
  std::istringstream in(text);
  while (std::getline(in, line))
    if (!line.empty() && line != "\r") last = line;
  return last;
}

// Writes `data` to the pipe; false when the reader has gone (EPIPE: SIGPIPE is blocked by the caller).
bool writeToPipe(int fd, const std::vector<uint8_t>& data) {
  for (size_t done = 0; done < data.size();) {
    const ssize_t n = ::write(fd, data.data() + done, data.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += size_t(n);
  }
  return true;
}

// Runs `argv` (argv[0] the program) with the files of `inputs` one after another on its standard input
// and its output into an anonymous log; returns its exit status (-1 when it could not start) and sets
// `why` to the log's last line. The files are read here (readFileBytes' rules: regular files), so no
// name of theirs ever reaches the program.
int runProgram(const std::vector<std::string>& argv, const std::vector<fs::path>& inputs, std::string& why) {
  const int log = anonymousLog();
  int pipeFds[2] = {-1, -1};
  if (log < 0 || ::pipe2(pipeFds, O_CLOEXEC) != 0) {
    why = std::string("cannot start ffmpeg: ") + std::strerror(errno);
    if (log >= 0) ::close(log);
    return -1;
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, pipeFds[0], STDIN_FILENO);
  posix_spawn_file_actions_adddup2(&actions, log, STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, log, STDERR_FILENO);
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, args[0], &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(pipeFds[0]);
  if (spawned != 0) {
    ::close(pipeFds[1]);
    ::close(log);
    why = std::string("cannot start ffmpeg: ") + std::strerror(spawned);
    return -1;
  }
  // A program that stops reading early ends the feed with EPIPE, not this process with SIGPIPE: the
  // signal is blocked in this thread while it writes, and one it raised is taken back before the
  // mask is restored.
  sigset_t pipeSignal, previous;
  sigemptyset(&pipeSignal);
  sigaddset(&pipeSignal, SIGPIPE);
  pthread_sigmask(SIG_BLOCK, &pipeSignal, &previous);
  bool fed = true;
  std::exception_ptr failure;
  try {
    for (const fs::path& input : inputs)
      if (!(fed = writeToPipe(pipeFds[1], readFileBytes(input)))) break;
  } catch (...) {
    failure = std::current_exception();  // a frame that cannot be read: ffmpeg sees the end, then throw
  }
  ::close(pipeFds[1]);
  if (!fed) {
    const struct timespec now {};
    sigtimedwait(&pipeSignal, nullptr, &now);
  }
  pthread_sigmask(SIG_SETMASK, &previous, nullptr);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  why = lastLine(log);
  ::close(log);
  if (failure) std::rethrow_exception(failure);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

}  // namespace

bool writeMovie(const fs::path& pngPattern, const FrameRange& frames, const fs::path& mp4,
                const fs::path& gif, const MovieOptions& options) {
  const std::string ffmpeg = findFfmpeg();
  if (ffmpeg.empty()) return false;
  // The frames go to ffmpeg on its standard input, one PNG after another, and the output is named with
  // the file: protocol: no path of the user's is read by ffmpeg as a pattern (%), a protocol (take:1),
  // or an option (-name).
  std::vector<fs::path> inputs;
  for (int f = frames.first; f <= frames.last; ++f) inputs.push_back(framePath(pngPattern, f));
  const std::vector<std::string> common = {ffmpeg,       "-nostdin",   "-y",
                                           "-loglevel",  "error",      "-f",
                                           "image2pipe", "-framerate", formatReal(options.frameRate),
                                           "-c:v",       "png",        "-i",
                                           "pipe:0",     "-frames:v",  std::to_string(frames.count())};
  auto encode = [&](const fs::path& target, std::vector<std::string> tail) {
    if (target.empty()) return;
    writeThroughTemporary(target, [&](const fs::path& temporary) {
      std::vector<std::string> argv = common;
      argv.insert(argv.end(), tail.begin(), tail.end());
      argv.push_back("file:" + fs::absolute(temporary).string());
      std::string why;
      const int status = runProgram(argv, inputs, why);
      std::error_code ec;
      std::string failure;
      if (status < 0)
        failure = why;
      else if (status != 0)
        failure = "ffmpeg failed (exit " + std::to_string(status) +
                  "): " + (why.empty() ? "no message" : oneLine(why));
      else if (fs::file_size(temporary, ec) == 0 || ec)
        failure = "ffmpeg ended well but wrote nothing";
      if (!failure.empty()) throw IoError({target.string(), 0}, failure);
    });
  };
  // libx264's 4:2:0 needs even sizes: an odd width or height gets one black column or row (right,
  // bottom), so a 1920x803 shot makes a 1920x804 movie. The frames are sRGB, whose primaries are
  // BT.709's: they are converted to Y'CbCr with BT.709's matrix in limited range (the scale filter's
  // out_color_matrix; ffmpeg's default would be BT.601's) and the stream is tagged so, which players
  // and browsers read to convert back.
  encode(mp4, {"-vf",
               "pad=ceil(iw/2)*2:ceil(ih/2)*2,scale=out_color_matrix=bt709:out_range=tv:flags=accurate_rnd,"
               "format=yuv420p",
               "-c:v",
               "libx264",
               "-pix_fmt",
               "yuv420p",
               "-colorspace",
               "bt709",
               "-color_primaries",
               "bt709",
               "-color_trc",
               "bt709",
               "-color_range",
               "tv",
               "-crf",
               "18",
               "-movflags",
               "+faststart",
               "-f",
               "mp4"});
  // The GIF at the frames' own size: people look at it beside the frames.
  const std::string filter = "fps=" + formatReal(options.gifFrameRate) +
                             ",split[a][b];[a]palettegen=stats_mode=diff[p];[b][p]paletteuse";
  encode(gif, {"-vf", filter, "-loop", "0", "-f", "gif"});
  return true;
}

}  // namespace hairgen
