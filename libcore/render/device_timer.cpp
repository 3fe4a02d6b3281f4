#include "libcore/render/device_timer.h"

#include <algorithm>
#include <cstdint>

namespace hairgen {

namespace {

// The entry of `name` in `times`, added at the end the first time.
DeviceTime& entry(std::vector<DeviceTime>& times, const std::string& name) {
  auto found = std::find_if(times.begin(), times.end(), [&](const DeviceTime& t) { return t.name == name; });
  if (found != times.end()) return *found;
  times.push_back({name});
  return times.back();
}

}  // namespace

DeviceTimer::DeviceTimer() {
  GLint bits = 0;
  glGetQueryiv(GL_TIMESTAMP, GL_QUERY_COUNTER_BITS, &bits);
  counting_ = bits > 0;
}

DeviceTimer::~DeviceTimer() {
  for (const Span& s : spans_) {
    glDeleteQueries(1, &s.start);
    glDeleteQueries(1, &s.end);
  }
}

DeviceTimer::Pass::Pass(DeviceTimer* timer, const char* name) : timer_(timer) {
  if (!timer_) return;
  Span s{name};
  if (timer_->counting_) {
    glCreateQueries(GL_TIMESTAMP, 1, &s.start);
    glCreateQueries(GL_TIMESTAMP, 1, &s.end);
    glQueryCounter(s.start, GL_TIMESTAMP);
  }
  span_ = timer_->spans_.size();
  timer_->spans_.push_back(std::move(s));
}

DeviceTimer::Pass::~Pass() {
  if (timer_ && timer_->counting_) glQueryCounter(timer_->spans_[span_].end, GL_TIMESTAMP);
}

DeviceTimer::Transfer::Transfer(DeviceTimer* timer, const char* name, size_t bytes)
    : timer_(timer), name_(name), bytes_(bytes) {}

DeviceTimer::Transfer::~Transfer() {
  if (!timer_) return;
  DeviceTime& t = entry(timer_->transfers_, name_);
  t.seconds += clock_.lap();
  t.bytes += bytes_;
  ++t.runs;
}

std::vector<DeviceTime> DeviceTimer::passes() const {
  std::vector<DeviceTime> times;
  for (const Span& s : spans_) {
    DeviceTime& t = entry(times, s.name);
    ++t.runs;
    if (!counting_) continue;
    GLuint64 start = 0, end = 0;
    glGetQueryObjectui64v(s.start, GL_QUERY_RESULT, &start);
    glGetQueryObjectui64v(s.end, GL_QUERY_RESULT, &end);
    t.seconds += end > start ? double(end - start) * 1e-9 : 0.0;  // nanoseconds
  }
  return times;
}

}  // namespace hairgen
