// The process runner: a program run with its stdout and stderr captured, as the farm's back ends run
// their scheduler's tools (sbatch, squeue, scancel, sinfo).
#pragma once

#include <string>
#include <vector>

namespace hairgen::farm {

struct ProcessResult {
  int status = -1;  // exit status, or 128 + signal
  std::string out, err;
};

// Runs argv (argv[0] found on PATH) with its stdout and stderr captured; both pipes are read together,
// so a child that fills one while the other is read never blocks, and only stderr's last 64 KiB are
// kept. Throws IoError when it cannot be started, its message ending in `hint` (what to do).
ProcessResult runProcess(const std::vector<std::string>& argv, const std::string& hint = {});

}  // namespace hairgen::farm
