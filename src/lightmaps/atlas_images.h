// Receivers' images copied into their atlases (texels/atlas_packing.h): each at its placement,
// with the padding ring around it filled from its own edge texels (clamp to edge), so that a
// bilinear filter at its edge reads only its own values.
#pragma once

#include <vector>

#include "core/image.h"
#include "texels/atlas_packing.h"

namespace sb {

// Atlas `atlas` of `layout` from the receivers' images (`images[r]` for placement r, all with
// `channels` channels; a null entry is skipped). Texels no receiver or padding covers hold
// `background`.
Image compose_atlas(const AtlasLayout& layout, int atlas, const std::vector<const Image*>& images,
                    int channels, float background);

}  // namespace sb
