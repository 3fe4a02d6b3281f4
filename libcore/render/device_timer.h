// Where a frame's time on the device goes (render --stats: device.passes, device.transfers): OpenGL
// timestamps (GL_TIMESTAMP, glQueryCounter) before and after each compute pass, read once the frame is
// done, so timing a pass waits for nothing the frame would not; and the host's time in each transfer
// between the host and the device. Needs a current OpenGL 4.5 context.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "libcore/render/gl_resources.h"
#include "libcore/render/renderer.h"
#include "libcore/util/stopwatch.h"

namespace hairgen {

class DeviceTimer {
 public:
  DeviceTimer();
  ~DeviceTimer();  // deletes its queries
  DeviceTimer(const DeviceTimer&) = delete;
  DeviceTimer& operator=(const DeviceTimer&) = delete;

  // The device's time in the work issued while a Pass lives, under `name` (the pass's shader,
  // "camera_keep"): from when the device reaches the Pass's start to when it has done that work. Make a
  // pass's programs before (a compile would count as the device's idle time). `timer` may be null: then
  // nothing is timed.
  class Pass {
   public:
    Pass(DeviceTimer* timer, const char* name);
    ~Pass();
    Pass(const Pass&) = delete;
    Pass& operator=(const Pass&) = delete;

   private:
    DeviceTimer* timer_;
    size_t span_ = 0;
  };

  // The host's time while a Transfer lives (the GL call's own, waiting for the device included), a
  // transfer of `bytes` under `name` ("camera_totals_read"). `timer` may be null.
  class Transfer {
   public:
    Transfer(DeviceTimer* timer, const char* name, size_t bytes);
    ~Transfer();
    Transfer(const Transfer&) = delete;
    Transfer& operator=(const Transfer&) = delete;

   private:
    DeviceTimer* timer_;
    const char* name_;
    size_t bytes_;
    Stopwatch clock_;
  };

  // The passes' device times (waits for the device to have done them: call once the frame is done),
  // each name once, in the order it first ran, its runs summed; seconds are 0 where the context's
  // timestamps do not count (GL_QUERY_COUNTER_BITS 0).
  std::vector<DeviceTime> passes() const;
  // The transfers' host times and bytes, alike.
  const std::vector<DeviceTime>& transfers() const { return transfers_; }

 private:
  struct Span {
    std::string name;
    GLuint start = 0, end = 0;  // timestamp queries; 0 where timestamps do not count
  };
  std::vector<Span> spans_;
  std::vector<DeviceTime> transfers_;
  bool counting_ = false;
};

}  // namespace hairgen
