// Visibility across a curved receiver's terminator (docs/methods.md, "Terminators"). A texel's
// visibility V = H / H0 is taken at its centre, and where the light lies below the horizon of
// the centre's shading normal H0 = 0 and no light counts there. But a texel is a square of
// surface: on a smooth-shaded sphere the terminator crosses it, and part of that square faces the
// light. Cycles, which bakes a texel over its square, gives such a texel the visibility of that
// lit part (1 on a sphere alone), and an engine that multiplies a lightmap by its own N·L blends
// it into the lit pixels beside it: left at 0, the terminator is a dark, faceted band.
//
// The rule: a texel where no light counts, some point of whose square (the middle half of its
// sides, as Blender bakes a texel, clipped to its triangle) has a shading normal under which a
// light's H0 > 0, takes the values of its 8 neighbours on the same piece of surface where a light
// counts, each weighted by the lights' H0 at its own point under the normal halfway between the
// two texels' (equally where no such normal sees a light). Shading normals come from the face's
// corners (TexelSpace::face_shading); on a flat receiver they do not turn, and nothing changes (a
// spot's cone edge or a point light in a wall's plane stays as it is).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "core/image.h"
#include "methods/light_lists.h"
#include "scene/lights.h"
#include "texels/texel_space.h"

namespace sb {

// The value a visibility image holds, until fill_terminators, at a covered texel where no light
// counts (V is never negative).
inline constexpr float kNoLightCounts = -1.0f;

// How an image marks a texel where no light counts.
enum class UncountedMark {
  value,    // three channels of V, kNoLightCounts where none counts; those left become 0
  flag_off  // two channels, V and a flag (a shadow mask's): flag 0 where none counts; a filled
            // texel's flag becomes 1
};

// Fills `image`'s uncounted covered texels as above from the lights `lights` (indices into
// `all`, ascending) and then, for UncountedMark::value, sets every texel still kNoLightCounts to
// 0. With `lists`, a texel weighs only those of `lights` its block lists (the rest give H0 = 0
// there under every normal of its square). With `blocks` (ascending, of LightLists::kSide²
// texels), only their texels are filled: a light's own image, beyond whose blocks it gives
// H0 = 0.
void fill_terminators(const TexelSpace& space, const std::vector<Light>& all,
                      const std::vector<std::size_t>& lights, UncountedMark mark, Image& image,
                      const LightLists* lists = nullptr,
                      std::optional<std::span<const std::uint32_t>> blocks = std::nullopt);

}  // namespace sb
