// Receivers' lightmaps packed into shared square atlases, as engines load them (Unity's
// lightmapScaleOffset, Godot's slices, Bevy's uv_rect): each receiver's square image keeps its own
// side and lies in one atlas with a ring of `padding` texels around it that only it fills, so a
// bilinear filter anywhere on its triangles reads none of another receiver's texels.
#pragma once

#include <array>
#include <vector>

#include "scene/scene.h"

namespace sb {

struct AtlasPlacement {
  int atlas = 0;     // which atlas
  int x = 0, y = 0;  // the receiver's first texel in it (column, row; row 0 is the top, v = 1)
  int side = 0;      // texels per side of the receiver's image
};

struct AtlasLayout {
  int padding = 0;
  std::vector<int> sizes;                  // per atlas, texels per side
  std::vector<AtlasPlacement> placements;  // per receiver, in the order given
};

// Rectangles of `sizes` (width, height) packed into one width × height area by stb_rect_pack's
// skyline bottom-left (libstb-dev), tallest first, ties in the given order: the same sizes give the
// same layout. Per rectangle, its lowest corner (x, y) and whether it fit.
struct RectanglePacking {
  std::vector<int> x, y;
  std::vector<bool> packed;
  bool all_packed() const;
};
RectanglePacking pack_rectangles(const std::vector<std::array<int, 2>>& sizes, int width,
                                 int height);

// Packs squares of `sides` (each at most settings.size − 2·padding) into as few atlases of
// settings.size² as the packer manages, the last shrunk to the smallest power-of-two fraction of
// settings.size that still holds its receivers. Skyline bottom-left (stb_rect_pack, libstb-dev),
// largest first, ties in the given order: the same sides give the same layout.
AtlasLayout pack_atlases(const std::vector<int>& sides, const AtlasSettings& settings);

// Where a receiver's lightmap UVs land in its atlas: atlas_uv = uv · scale + offset, as
// {scale_u, scale_v, offset_u, offset_v}. `v_up`: UVs with v up (OBJ, Blender, Unity; pixel row 0
// at v = 1), else glTF's (v down, row 0 at v = 0; KHR_texture_transform's convention).
std::array<double, 4> atlas_scale_offset(const AtlasPlacement& p, int atlas_size, bool v_up);

}  // namespace sb
