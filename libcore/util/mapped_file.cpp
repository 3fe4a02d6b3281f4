#include "libcore/util/mapped_file.h"

#include <signal.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstring>
#include <mutex>

#include "libcore/util/error.h"
#include "libcore/util/file_util.h"

namespace hairgen {

namespace {

// The mappings a SIGBUS may come from, readable from the handler: a fixed table, each slot free (0),
// being filled (1) or live (2), as the interrupt cleanup's temporaries are (file_util.cpp).
struct GuardSlot {
  std::atomic<int> state{0};
  uintptr_t begin = 0, end = 0;
  char message[4352];  // "hairgen COMMAND: error: FILE: the file shrank while it was read\n"
  size_t length = 0;
};
std::array<GuardSlot, 64> gGuarded;
char gCommand[64] = "";

constexpr char kShrank[] = "the file shrank while it was read";

int guard(const uint8_t* data, uint64_t size, const std::string& name) {
  const std::string line = std::string("hairgen ") + gCommand + ": error: " + name + ": " + kShrank + "\n";
  if (line.size() > sizeof gGuarded[0].message) return -1;
  for (size_t i = 0; i < gGuarded.size(); ++i) {
    int expected = 0;
    if (!gGuarded[i].state.compare_exchange_strong(expected, 1)) continue;
    GuardSlot& slot = gGuarded[i];
    slot.begin = reinterpret_cast<uintptr_t>(data);
    slot.end = slot.begin + size;
    std::memcpy(slot.message, line.data(), line.size());
    slot.length = line.size();
    slot.state.store(2);
    return int(i);
  }
  return -1;  // every slot taken: the mapping works, only a shrinking file ends the process by SIGBUS
}

extern "C" void onBusError(int signal, siginfo_t* info, void*) {
  const uintptr_t at = reinterpret_cast<uintptr_t>(info->si_addr);
  for (const GuardSlot& slot : gGuarded) {
    if (slot.state.load() != 2 || at < slot.begin || at >= slot.end) continue;
    removeTemporariesOfWritesInFlight();
    for (size_t done = 0; done < slot.length;) {
      const ssize_t n = ::write(STDERR_FILENO, slot.message + done, slot.length - done);
      if (n <= 0) break;
      done += size_t(n);
    }
    ::_exit(int(ExitCode::kBadInput));
  }
  // Not a mapping's: the default action, when the instruction runs again.
  struct sigaction fallback {};
  fallback.sa_handler = SIG_DFL;
  sigemptyset(&fallback.sa_mask);
  ::sigaction(signal, &fallback, nullptr);
}

}  // namespace

std::shared_ptr<FileMapping> FileMapping::map(int fd, uint64_t size, const std::string& name) {
  if (size == 0 || size > uint64_t(SIZE_MAX)) return nullptr;
  void* data = ::mmap(nullptr, size_t(size), PROT_READ | PROT_WRITE, MAP_PRIVATE, fd, 0);
  if (data == MAP_FAILED) return nullptr;
  // Read from the start on: the kernel reads ahead of the faults.
  ::madvise(data, size_t(size), MADV_WILLNEED);
  uint8_t* bytes = static_cast<uint8_t*>(data);
  return std::shared_ptr<FileMapping>(new FileMapping(bytes, size, guard(bytes, size, name)));
}

FileMapping::~FileMapping() {
  if (guardSlot_ >= 0) gGuarded[size_t(guardSlot_)].state.store(0);  // before the pages go
  ::munmap(data_, size_t(size_));
}

void FileMapping::release(uint64_t offset, uint64_t bytes) const {
  const uint64_t page = uint64_t(::sysconf(_SC_PAGESIZE));
  const uint64_t begin = (offset + page - 1) / page * page,
                 end = std::min(offset + bytes, size_) / page * page;
  if (end > begin) ::madvise(data_ + begin, size_t(end - begin), MADV_DONTNEED);
}

void installMappingGuard(const std::string& command) {
  static std::once_flag once;
  const size_t n = std::min(command.size(), sizeof gCommand - 1);
  std::memcpy(gCommand, command.data(), n);
  gCommand[n] = '\0';
  std::call_once(once, [] {
    struct sigaction action {};
    action.sa_sigaction = onBusError;
    action.sa_flags = SA_SIGINFO;
    sigemptyset(&action.sa_mask);
    ::sigaction(SIGBUS, &action, nullptr);
  });
}

}  // namespace hairgen
