// The `convolution` method: soft-shadow textures by FFT convolution (Soler & Sillion 1998),
// convolution_bake.cpp.
#pragma once

#include <string>
#include <vector>

#include "bake.h"
#include "lights.h"
#include "mesh.h"
#include "texel_space.h"
#include "virtual_configuration.h"

namespace sb {

struct ConvolutionInputs {
  const std::vector<Light>* lights = nullptr;
  const Mesh* receiver = nullptr;     // the receiver's own mesh (for its texel size)
  std::vector<const Mesh*> blockers;  // every blocker but the receiver itself
  Quantity quantity = Quantity::visibility;
  int max_image = 4096;  // largest blocker image side, pixels
};

// Bakes one receiver: for each light, the virtual configuration (D towards the receiver's lit
// texels, planes by the penumbra error metric), the source kernel and the blocker image, their
// FFT convolution, and a projective bilinear lookup per texel; lights combined as
// V = Σ H0_l·V_l / Σ H0_l (or H = Σ H0_l·V_l). Appends one report per light to `reports`.
Image bake_convolution(const TexelSpace& texels, const ConvolutionInputs& in,
                       std::vector<PairReport>* reports);

// World size of one texel of `mesh`'s lightmap at width × height, metres: the square root of
// world area per covered texel area.
double texel_size(const Mesh& mesh, int width, int height);

}  // namespace sb
