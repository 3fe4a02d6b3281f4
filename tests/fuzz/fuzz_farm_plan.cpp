// Fuzzes the farm plan reader (farm/plan.h): the input is a plan's JSON text. farmPlanFromJson
// reads it and checks it by validateFarmPlan's rules (names, control characters, paths inside the
// plan's folder, a hairgen executable, bounded counts). A plan it accepts must keep what `farm submit`
// relies on: no string with a control character (it would split a script's line), ids that are array
// indices, and JSON that reads back as the same plan. Findings: see fuzz_target.h.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "farm/plan.h"
#include "tests/fuzz/fuzz_target.h"

namespace {

bool hasControl(const std::string& s) {
  for (char c : s)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) return true;
  return false;
}

// Every string of an accepted plan a script could hold.
void checkAccepted(const hairgen::FarmPlan& plan) {
  using hairgen::fuzz::finding;
  if (hasControl(plan.setup) || hasControl(plan.directory)) finding("a control character in a path");
  for (const std::string& o : plan.overrides)
    if (hasControl(o)) finding("a control character in an override");
  for (const hairgen::FarmTask& t : plan.tasks) {
    if (hairgen::farmArrayIndex(t) < 0 || hairgen::farmArrayIndex(t) > hairgen::kFarmMaxGroupTasks)
      finding("an array index out of range");
    for (const auto* list : {&t.command, &t.inputs, &t.outputs, &t.deps})
      for (const std::string& s : *list)
        if (hasControl(s)) finding("a control character in a task");
    if (hasControl(t.id) || hasControl(t.group) || t.group.find('/') != std::string::npos)
      finding("an id or group a file name could not hold");
  }
  if (hairgen::toJson(hairgen::farmPlanFromJson(hairgen::toJson(plan), "again")) != hairgen::toJson(plan))
    finding("an accepted plan does not read back as itself");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const nlohmann::ordered_json json = nlohmann::ordered_json::parse(data, data + size, nullptr, false);
  if (json.is_discarded()) return 0;
  std::optional<hairgen::FarmPlan> plan;
  hairgen::fuzz::readOrReject("farmPlanFromJson",
                              [&] { plan = hairgen::farmPlanFromJson(json, "fuzz.json"); });
  if (plan) checkAccepted(*plan);
  return 0;
}
