#include "libcore/util/mapped_file.h"

#include <signal.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <mutex>

#include "libcore/util/error.h"
#include "libcore/util/signal_slots.h"

namespace hairgen {

namespace {

// The mappings a SIGBUS may come from, for the handler to find (signal_slots.h).
struct Guarded {
  std::atomic<bool> zeroed{false};  // its pages were made zeros after a fault
  uintptr_t begin = 0, end = 0;
  char name[4096];
};
SignalSlots<Guarded, 64> gGuarded;

// The first fault not yet reported (requireMappingsWhole): its file's name and the size it was mapped at.
struct Fault {
  std::atomic<int> state{0};  // 0 none, 1 being written, 2 recorded
  char name[4096];
  uint64_t size = 0;
};
Fault gFault;

int guard(const uint8_t* data, uint64_t size, const std::string& name) noexcept {
  if (name.size() >= sizeof(Guarded::name)) return -1;
  const int slot = gGuarded.claim();
  if (slot < 0) return -1;  // every slot taken: the mapping works, only a fault in it is the default SIGBUS
  Guarded& g = gGuarded[slot];
  g.begin = reinterpret_cast<uintptr_t>(data);
  g.end = g.begin + size;
  g.zeroed.store(false);
  std::memcpy(g.name, name.c_str(), name.size() + 1);
  gGuarded.markLive(slot);
  return slot;
}

// Async-signal-safe: atomics, memcpy, mmap, sigaction, raise.
extern "C" void onBusError(int signal, siginfo_t* info, void*) {
  const int savedErrno = errno;
  const uintptr_t at = reinterpret_cast<uintptr_t>(info->si_addr);
  const bool fault = info->si_code > 0;  // not sent by kill or raise
  Guarded* slot =
      fault ? gGuarded.findLive([&](const Guarded& g) { return at >= g.begin && at < g.end; }) : nullptr;
  if (slot) {
    int none = 0;
    if (gFault.state.compare_exchange_strong(none, 1)) {
      std::memcpy(gFault.name, slot->name, sizeof gFault.name);
      gFault.size = slot->end - slot->begin;
      gFault.state.store(2);
    }
    // The mapping's pages become zeros, at the same addresses: the faulting instruction runs again and
    // reads them (as does any other thread that faulted there meanwhile). Where they cannot be made
    // zeros, the default action, below.
    if (slot->zeroed.exchange(true) ||
        ::mmap(reinterpret_cast<void*>(slot->begin), slot->end - slot->begin, PROT_READ | PROT_WRITE,
               MAP_PRIVATE | MAP_ANONYMOUS | MAP_FIXED, -1, 0) != MAP_FAILED) {
      errno = savedErrno;
      return;
    }
  }
  struct sigaction fallback {};
  fallback.sa_handler = SIG_DFL;
  sigemptyset(&fallback.sa_mask);
  ::sigaction(signal, &fallback, nullptr);
  if (!fault) ::raise(signal);  // a fault instead runs again, and gets the default
  errno = savedErrno;
}

}  // namespace

std::shared_ptr<FileMapping> FileMapping::map(int fd, uint64_t size, const std::string& name) {
  if (size == 0 || size > uint64_t(SIZE_MAX)) return nullptr;
  void* data = ::mmap(nullptr, size_t(size), PROT_READ | PROT_WRITE, MAP_PRIVATE, fd, 0);
  if (data == MAP_FAILED) return nullptr;
  // Read from the start on: the kernel reads ahead of the faults.
  ::madvise(data, size_t(size), MADV_WILLNEED);
  uint8_t* bytes = static_cast<uint8_t*>(data);
  const int slot = guard(bytes, size, name);
  // Owned from here on: where the shared_ptr cannot be made, it deletes the mapping (and frees its slot).
  return std::shared_ptr<FileMapping>(new FileMapping(bytes, size, slot));
}

FileMapping::~FileMapping() {
  gGuarded.release(guardSlot_);  // before the pages go
  ::munmap(data_, size_t(size_));
}

void FileMapping::release(uint64_t offset, uint64_t bytes) const {
  const uint64_t page = uint64_t(::sysconf(_SC_PAGESIZE));
  const uint64_t begin = (offset + page - 1) / page * page,
                 end = std::min(offset + bytes, size_) / page * page;
  if (end > begin) ::madvise(data_ + begin, size_t(end - begin), MADV_DONTNEED);
}

void installMappingGuard() {
  static std::once_flag once;
  std::call_once(once, [] {
    struct sigaction action {};
    action.sa_sigaction = onBusError;
    action.sa_flags = SA_SIGINFO;
    sigemptyset(&action.sa_mask);
    ::sigaction(SIGBUS, &action, nullptr);
  });
}

void requireMappingsWhole() {
  if (gFault.state.load() != 2) return;
  const std::string name = gFault.name;
  const uint64_t mapped = gFault.size;
  gFault.state.store(0);
  struct stat st {};
  if (::stat(name.c_str(), &st) != 0 || uint64_t(st.st_size) < mapped)
    throw InputError({name, 0}, kFileShrank);
  throw IoError({name, 0}, kPageUnreadable);
}

}  // namespace hairgen
