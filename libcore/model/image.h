// Images as float planes: what the renderer produces, `hairgen diff` compares and the EXR writer writes.
#pragma once

#include <string>
#include <vector>

namespace hairgen {

// Float planes, rows top to bottom.
struct Image {
  int width = 0, height = 0;
  std::vector<std::string> channels;  // names, in plane order
  std::vector<std::vector<float>> planes;
  // The plane of a channel; throws std::out_of_range when there is none.
  const std::vector<float>& plane(const std::string& name) const;
  bool has(const std::string& name) const;
  float at(const std::string& name, int x, int y) const { return plane(name)[size_t(y) * width + x]; }
};

}  // namespace hairgen
