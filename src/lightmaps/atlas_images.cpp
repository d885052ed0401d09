// Atlas images (atlas_images.h).
#include "lightmaps/atlas_images.h"

#include <algorithm>

namespace sb {

Image compose_atlas(const AtlasLayout& layout, int atlas, const std::vector<const Image*>& images,
                    int channels, float background) {
  const int size = layout.sizes[std::size_t(atlas)];
  Image out(size, size, channels, background);
  const int pad = layout.padding;
  for (std::size_t r = 0; r < layout.placements.size() && r < images.size(); ++r) {
    const AtlasPlacement& p = layout.placements[r];
    const Image* image = images[r];
    if (p.atlas != atlas || !image) continue;
    for (int y = -pad; y < p.side + pad; ++y) {
      const int ty = p.y + y;
      if (ty < 0 || ty >= size) continue;
      const int sy = std::clamp(y, 0, image->height - 1);
      for (int x = -pad; x < p.side + pad; ++x) {
        const int tx = p.x + x;
        if (tx < 0 || tx >= size) continue;
        const int sx = std::clamp(x, 0, image->width - 1);
        std::copy_n(image->at(sx, sy), channels, out.at(tx, ty));
      }
    }
  }
  return out;
}

}  // namespace sb
