#include "farm/process.h"

#include <poll.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "libcore/util/error.h"

extern char** environ;

namespace hairgen::farm {
namespace {

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

}  // namespace

ProcessResult runProcess(const std::vector<std::string>& argv, const std::string& hint) {
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
    throw IoError("cannot run " + argv[0] + ": " + std::strerror(spawned) + hint);
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

}  // namespace hairgen::farm
