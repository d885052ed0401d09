"""Blender's own Preetham sky (its Sky Texture node, sky_type PREETHAM) rendered through Cycles'
equirectangular camera, as the cross-check of shadowbake's analytic sky (src/scene/sky_models.h):
`Sky.PreethamMatchesBlendersSkyTexture` compares shadowbake's map with these files pixel by pixel.

    blender -b --factory-startup -P tests/tools/blender_preetham_sky.py -- OUT_FOLDER

Writes OUT_FOLDER/preetham_t<T>.exr (128 × 64, 32-bit float, linear Rec.709 RGB) for each
turbidity T below, the sun at SUN_DIRECTION (towards the sun, Z up). Each pixel is the sky at its
centre's direction by Cycles' equirectangular mapping (middle column +X, top row the zenith, u
growing towards -Y; the filter made a point so that a pixel is its centre), as shadowbake maps a
sky's map. The files are rewritten from their pixels alone, so their bytes do not hold Cycles'
render times.
"""

import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(sys.argv[sys.argv.index("-P") + 1]))
sys.path.insert(0, os.path.join(HERE, "..", "..", "scenes"))
import blender_assets as ba  # noqa: E402

SUN_ELEVATION_DEG = 38.0
SUN_AZIMUTH_DEG = 215.0  # from +X towards +Y
TURBIDITIES = (2.2, 6.0)
WIDTH, HEIGHT = 128, 64

out = os.path.abspath(sys.argv[sys.argv.index("--") + 1])
os.makedirs(out, exist_ok=True)
elevation, azimuth = math.radians(SUN_ELEVATION_DEG), math.radians(SUN_AZIMUTH_DEG)
sun = (math.cos(azimuth) * math.cos(elevation), math.sin(azimuth) * math.cos(elevation),
       math.sin(elevation))

for turbidity in TURBIDITIES:
    ba.reset()
    sky = ba.sky_world("PREETHAM")
    sky.turbidity = turbidity
    sky.sun_direction = sun
    path = os.path.join(out, f"preetham_t{turbidity:g}.exr")
    ba.render_world_equirectangular(path, WIDTH, HEIGHT, samples=4, color_depth="32",
                                    filter_width=0.01)
    print("wrote", path)
