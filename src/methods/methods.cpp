// The registry of bake method names, so the scene reader and the CLI can reject an unknown
// method with the list of known ones.
#include "scene/scene.h"

namespace sb {

const std::vector<std::string>& known_methods() {
  static const std::vector<std::string> names = {"convolution", "accumulation", "pcf",     "pcss",
                                                 "adaptive-pcf", "erosion",      "chun-oh", "reference"};
  return names;
}

}  // namespace sb
