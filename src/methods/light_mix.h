// How every method combines lights into a receiver's texel values, and keeps each light's own
// values for per-light outputs. The rule is the reference's (docs/methods.md, its opening):
// per texel and colour channel, light l's visibility V_l is weighted by its unoccluded
// irradiance H0_l (closed form, Light::unoccluded_irradiance); a light with H0_l = 0 there, or
// one the method leaves out at the texel (none of its samples contributes), adds nothing; then
//   visibility  V = Σ_l H0_l·V_l / Σ_l H0_l   (0 where the sum of weights is 0, but for a
//               texel on a smooth receiver's terminator: terminator_fill.h),
//   irradiance  H = Σ_l H0_l·V_l              (W/m²),
// summed in double over lights in scene order and written as float.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <span>
#include <vector>

#include "core/image.h"
#include "core/tiled_images.h"
#include "methods/light_lists.h"
#include "scene/lights.h"
#include "texels/texel_space.h"

namespace sb {

// Which per-light images a mix keeps beside the combined one.
struct KeepPerLight {
  bool values = false;      // MixedImages::per_light
  bool visibility = false;  // MixedImages::per_light_visibility
  bool any() const { return values || visibility; }
};

// A method's values for one receiver: the combined image and, when kept, per light of the scene
// (a mesh light's parts together, by the same rule: V = Σ H0·V / Σ H0 over them)
//  - per_light: light l's V_l, or H0_l·V_l for irradiance, at the texels where it counts, 0
//    elsewhere; width × height RGB, uncovered texels 0;
//  - per_light_visibility: two channels, light l's visibility (its H0-weighted mean over colour
//    channels, Σ_c H0_c·V_c / Σ_c H0_c) and 1 where it counts at the texel; (1, 0) elsewhere,
//    uncovered texels included (what a shadow mask holds, lightmaps/shadowmask.h).
// Each is kept by tiles (TiledImages): with light lists, a light's tiles are the blocks its lists
// give it (its parts' together), so the images cost what the lights reach, not lights × texels.
struct MixedImages {
  Image image;
  // The most lights that reach any one texel (H0 > 0 there): how many a texel sums at most.
  std::uint32_t most_lights = 0;
  TiledImages per_light;             // empty unless kept
  TiledImages per_light_visibility;  // empty unless kept
};

// Empty per-light images of a width × height receiver, each spilling to a scratch file as it
// is given back (TiledImages): values (0 beyond a light's tiles) and visibility ((1, 0) beyond
// them).
TiledImages per_light_values(std::size_t lights, int width, int height);
TiledImages per_light_visibilities(std::size_t lights, int width, int height);

class LightMix {
 public:
  // How the method visits (light, texel) pairs: all of a texel's lights at once (add, write), or
  // light by light (set, then finish writes; each texel's sums are kept until then, not each
  // light's values). light_by_light is light_major with each light's turn bracketed by
  // begin_light and end_light: a kept light's values are then made at its turn and finished
  // (and spilled, TiledImages) at its end, so that memory holds one light's values at a time.
  // `lists`, where given, says which lights may reach each block of texels (the terminators'
  // fill weighs those alone; the others add exactly 0).
  enum class Order { texel_major, light_major, light_by_light };
  LightMix(const TexelSpace& space, const std::vector<Light>& lights, Quantity quantity,
           Order order, KeepPerLight keep, const LightLists* lists = nullptr);

  // H0_l at texel t (per channel, W/m²): a light whose H0 is 0 everywhere need not be estimated.
  Vec3 unoccluded(std::size_t light, std::size_t texel) const;

  // Methods that estimate a texel's lights together, in light order: add each counted light's
  // H0 and V to the texel's Sum, then write() it. Many threads may do this for distinct texels.
  struct Sum {
    Vec3 h = Vec3::Zero(), h0 = Vec3::Zero();
    std::uint32_t lights = 0;  // those added with H0 > 0
  };
  void add(Sum& sum, std::size_t light, std::size_t texel, const Vec3& h0, const Vec3& v);
  void write(std::size_t texel, const Sum& sum);

  // Methods that run light by light: light l's visibility at texel t (per channel, [0, 1]); a
  // pair never set is left out. Its H0 and H0·V are added to the texel's sums at once, so the
  // lights are set one after another, in scene order, each pair at most once (as a texel-major
  // method adds them); many threads may set distinct texels of one light.
  void set(std::size_t light, std::size_t texel, const Vec3& v);
  // The same for a caller that knows the texel's pixel (x, y), which then need not be read from
  // its record (a 4096² receiver's records are half a gigabyte).
  void set(std::size_t light, std::size_t texel, int x, int y, const Vec3& v);

  // light_by_light: light l's turn begins (before its first set) and ends (after its last).
  // A light whose turn never comes adds nothing, and its kept images are the fill.
  void begin_light(std::size_t light);
  void end_light(std::size_t light);

  MixedImages finish();

 private:
  void keep(std::size_t light, std::size_t texel, const Vec3& h0, const Vec3& v);
  void keep_output(std::size_t output, std::size_t texel, const Vec3& h0, const Vec3& v);
  std::array<float, 3> value_start() const;  // a value image's start over its tiles
  // Output o's kept images over `tiles`, at their start.
  void reserve(std::size_t output, std::span<const std::uint32_t> tiles);
  // Output o's kept images made final (the terminators filled), then spilled.
  void finish_output(std::size_t output, const std::vector<std::size_t>& parts);

  const TexelSpace& space_;
  const std::vector<Light>& lights_;
  const LightLists* lists_;
  Quantity quantity_;
  KeepPerLight keep_;
  MixedImages out_;
  bool direct_ = false;  // one light's visibility, light-major: set() writes the image itself
  // light_by_light, each output one light: its kept images are made at its turn, over
  // turn_tiles_[output] (the blocks its lists give it).
  bool by_turn_ = false;
  std::vector<std::vector<std::uint32_t>> turn_tiles_;
  std::atomic<std::uint32_t> most_lights_{0};  // MixedImages::most_lights, as texels are written
  // Light-major methods' sums per texel until finish() (48 bytes a texel, whatever the number
  // of lights); empty for texel-major ones.
  FreshVector<Sum> set_sums_;
  // Per scene light (Light::output): its parts' sums per texel, for a mesh light whose
  // images are kept; empty for the others.
  std::vector<std::vector<Sum>> sums_;
};

}  // namespace sb
