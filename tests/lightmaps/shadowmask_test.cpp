// Tests of shadow-mask channels and images (src/lightmaps/shadowmask.h): lights that meet get
// different channels, lights that never meet share one, a fifth overlapping light is left out
// with a warning naming it, and the mask holds each channel's light's visibility.
#include "lightmaps/shadowmask.h"
#include "methods/light_mix.h"

#include <gtest/gtest.h>

namespace sb {
namespace {

std::vector<LightDesc> named(int count) {
  std::vector<LightDesc> lights(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) {
    lights[std::size_t(i)].name = std::string(1, char('a' + i));
    lights[std::size_t(i)].line = 10 * (i + 1);
  }
  return lights;
}

LightOverlaps all_meet(std::size_t count) {
  LightOverlaps o(count);
  std::fill(o.overlaps.begin(), o.overlaps.end(), std::uint8_t(1));
  return o;
}

TEST(ShadowmaskChannels, SixOverlappingLightsFillFourChannelsAndWarnOfTwo) {
  const ShadowmaskChannels c = assign_shadowmask_channels(all_meet(6), named(6), "s.toml");
  EXPECT_EQ(c.channel, (std::vector<int>{0, 1, 2, 3, -1, -1}));
  ASSERT_EQ(c.warnings.size(), 2u);
  EXPECT_EQ(c.warnings[0].rfind("s.toml:50: light 'e': no shadow-mask channel is free", 0), 0u)
      << c.warnings[0];
  EXPECT_NE(c.warnings[0].find("'a' (R), 'b' (G), 'c' (B), 'd' (A)"), std::string::npos);
  EXPECT_EQ(c.warnings[1].rfind("s.toml:60: light 'f'", 0), 0u) << c.warnings[1];
}

TEST(ShadowmaskChannels, LightsThatNeverMeetShareAChannel) {
  // Two rooms of three lights each: within a room they meet, across rooms they do not.
  LightOverlaps o(6);
  for (std::size_t a = 0; a < 6; ++a)
    for (std::size_t b = 0; b < 6; ++b) o.overlaps[a * 6 + b] = (a < 3) == (b < 3);
  const ShadowmaskChannels c = assign_shadowmask_channels(o, named(6), "s.toml");
  EXPECT_EQ(c.channel, (std::vector<int>{0, 1, 2, 0, 1, 2}));
  EXPECT_TRUE(c.warnings.empty());
}

// Visibility images as a bake keeps them, by tiles.
TiledImages tiled(const std::vector<Image>& images) {
  TiledImages out = per_light_visibilities(images.size(), images[0].width, images[0].height);
  for (std::size_t l = 0; l < images.size(); ++l) out.assign(l, images[l]);
  return out;
}

TEST(ShadowmaskChannels, OverlapsComeFromCoveredTexelsWhereBothReach) {
  // Three texels; light 0 reaches texels 0 and 1, light 1 texel 1, light 2 texel 2 (uncovered).
  std::vector<Image> v(3, Image(3, 1, 2, 0.0f));
  v[0].pixels[1] = v[0].pixels[3] = 1;
  v[1].pixels[3] = 1;
  v[2].pixels[5] = 1;
  LightOverlaps o(3);
  add_overlaps(tiled(v), {1, 1, 0}, o);
  EXPECT_TRUE(o.meet(0, 1));
  EXPECT_TRUE(o.meet(1, 0));
  EXPECT_FALSE(o.meet(0, 2));
  EXPECT_FALSE(o.meet(1, 2));
}

TEST(ShadowmaskImage, EachChannelHoldsItsLightsVisibility) {
  // Two texels; lights 0 and 2 share channel R and reach one texel each; light 1 is G; light 3
  // was left out.
  std::vector<Image> v(4, Image(2, 1, 2, 0.0f));
  const float values[4][4] = {
      {0.25f, 1, 1, 0}, {0.5f, 1, 0.75f, 1}, {1, 0, 0.125f, 1}, {0, 1, 0, 1}};
  for (int l = 0; l < 4; ++l)
    for (int i = 0; i < 4; ++i) v[std::size_t(l)].pixels[std::size_t(i)] = values[l][i];
  const Image mask = compose_shadowmask(tiled(v), {0, 1, 0, -1}, 2, 1);
  ASSERT_EQ(mask.channels, 4);
  EXPECT_FLOAT_EQ(mask.at(0, 0)[0], 0.25f);
  EXPECT_FLOAT_EQ(mask.at(1, 0)[0], 0.125f);
  EXPECT_FLOAT_EQ(mask.at(0, 0)[1], 0.5f);
  EXPECT_FLOAT_EQ(mask.at(1, 0)[1], 0.75f);
  EXPECT_FLOAT_EQ(mask.at(0, 0)[2], 1.0f);  // no light holds B or A
  EXPECT_FLOAT_EQ(mask.at(1, 0)[3], 1.0f);
}

}  // namespace
}  // namespace sb
