#include "libcore/model/image.h"

#include <stdexcept>

namespace hairgen {

const std::vector<float>& Image::plane(const std::string& name) const {
  for (size_t i = 0; i < channels.size(); ++i)
    if (channels[i] == name) return planes[i];
  throw std::out_of_range("no channel " + name);
}

bool Image::has(const std::string& name) const {
  for (const std::string& c : channels)
    if (c == name) return true;
  return false;
}

}  // namespace hairgen
