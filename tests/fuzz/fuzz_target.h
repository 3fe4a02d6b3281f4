// What every fuzz target counts as a finding (tests/fuzz, scripts/fuzz.sh).
//
// A reader given arbitrary bytes may accept them or reject them with a hairgen::Error (the typed
// errors of libcore/util/error.h, which the command line turns into one line and exit code 2). Anything
// else is a finding: another exception, a crash, a sanitizer report (ASan, UBSan), a leak, a timeout
// or an allocation past libFuzzer's -rss_limit_mb / -malloc_limit_mb.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <typeinfo>

#include "libcore/util/error.h"

namespace hairgen::fuzz {

// Runs `read`; a hairgen::Error is a normal rejection, any other exception aborts (a finding, saved
// by libFuzzer as crash-<sha1>).
template <typename Read>
void readOrReject(const char* what, Read&& read) {
  try {
    read();
  } catch (const Error&) {
    // The reader refused the input with a typed error: what it is meant to do.
  } catch (const std::exception& e) {
    std::fprintf(stderr, "FINDING: %s threw %s, not a hairgen::Error: %s\n", what, typeid(e).name(),
                 e.what());
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "FINDING: %s threw something that is not a std::exception\n", what);
    std::abort();
  }
}

// A finding that is not an exception: the reader accepted what it must refuse.
[[noreturn]] inline void finding(const char* message) {
  std::fprintf(stderr, "FINDING: %s\n", message);
  std::abort();
}

}  // namespace hairgen::fuzz
