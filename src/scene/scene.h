// The scene as the user describes it: bake settings, objects (meshes with flags and transforms)
// and area lights. Read from a TOML file by load_scene (scene_file.cpp); docs/scene-format.md is
// the user's reference for every key.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "core/error.h"
#include "core/geometry.h"

namespace sb {

// visibility V = H / H0 and irradiance H of the lights (methods/light_mix.h); ambient occlusion,
// the cosine-weighted open fraction of the hemisphere within [bake] ao_distance, no light taking
// part (methods/ambient_occlusion.h; baked by the method of that name alone).
enum class Quantity { visibility, irradiance, ambient_occlusion };

// Whether `name` can stand in a file name on every platform outputs travel to: letters, digits,
// '_', '.', '-', not starting with '.' (object names, and light names with per-light files).
bool is_file_name_part(std::string_view name);
bool is_file_name_char(char c);  // one character of such a name

// A method's own [bake] setting's value: a switch, a whole number, a number or a word.
using SettingValue = std::variant<bool, std::int64_t, double, std::string>;

// One [bake] key that a method reads beyond the keys of every bake, as its registry entry
// declares it (methods/method.h, MethodEntry::own_settings): its default, which also gives the
// value's type, and how a value is checked. The scene reader, the command line, the manifest and
// the shard files know a method's settings only through these.
struct SettingSpec {
  std::string key;
  SettingValue fallback;
  std::int64_t lo = 0, hi = 0;  // a whole number's range
  // What a valid number or word is, for errors ("a number > 0", "\"product\" or \"sum\"").
  std::string requirement;
  std::function<bool(const SettingValue&)> valid;  // beyond the type and range; may be empty
};

// What the scene reader is told of the bake methods by the layer that knows them
// (methods/method.h, method_vocabulary()): the scene layer knows no method, and checks a file's
// [bake] method and method keys against this.
struct MethodVocabulary {
  std::vector<std::string> names;  // every method, in the order docs/methods.md lists them
  // The method that alone bakes ambient occlusion, and bakes nothing else.
  std::string ambient_occlusion;
  std::vector<SettingSpec> settings;  // every method's own [bake] keys, each once
};

struct BakeSettings {
  int resolution = 512;  // texels per side of each receiver's lightmap
  // When > 0, each receiver's lightmap side instead follows from its surface area: this many
  // texels per metre of its surface (texels/lightmap_sizes.h), times its lightmap_scale.
  double texels_per_metre = 0;
  // The method's name: the registry's first (methods/registry.cpp) unless the scene or the
  // command line names another; MethodRegistry.DefaultIsTheFirst checks that the two agree.
  std::string method = "backprojection";
  Quantity quantity = Quantity::visibility;
  int samples = 256;  // light samples per texel, for sampling methods (rays, for ambient occlusion)
  // ambient occlusion: metres along a ray within which a blocker occludes it (Blender's default)
  double ao_distance = 10.0;
  // W/m²; > 0: each point, spot, sphere, rectangle and disk light without a `range` is given
  // the range at which its irradiance on a surface facing it falls to this floor (a file whose
  // lights carry none, such as Blender's exports; receiver_stages.h, placed_lights). 0: such
  // lights reach everywhere.
  double irradiance_floor = 0;
  int margin = 4;  // texels of dilation around UV charts
  // After dilation, adjust the texels along UV seams so that bilinear lookups on the two sides
  // agree (texels/seams.h); false leaves them as baked, and only measures the seams.
  bool seams = true;
  std::uint64_t seed = 0;  // sampling seed; same seed, same bytes
  // Bytes the bake may use (memory_budget.h); 0: the default, 3/4 of the physical memory.
  std::uint64_t max_memory = 0;
  // Each method's own [bake] keys (SettingSpec) that the scene file or the command line set; a
  // key not here has its method's default. Methods read them with setting_whole() and its
  // kin, and the command line sets them with set_setting() (methods/method.h).
  std::map<std::string, SettingValue, std::less<>> own;
};

// Sets a method's own key in `bake` to `value`, a whole number made a number where `spec` takes
// one; not checked against its range.
void set_own_setting(BakeSettings& bake, const SettingSpec& spec, SettingValue value);

struct ObjectDesc {
  std::string name;            // unique; the output file stem
  std::filesystem::path mesh;  // resolved against the scene file's folder
  bool receiver = true;
  bool blocker = true;
  int uv_channel = 0;
  // uv = "auto": the bake makes the lightmap UVs (texels/auto_uv.h); uv_channel (0) then names
  // only the texture UVs that a glTF of the bake carries.
  bool auto_uv = false;
  // A receiver whose lightmap UVs cover no texel is an error unless this is set (its lightmap is
  // then written black, with a warning).
  bool allow_uncovered = false;
  Affine3 transform = Affine3::Identity();  // scale, then rotate (X, Y, Z), then translate
  // With [bake] texels_per_metre: this object's density relative to the scene's (Unity's "Scale
  // In Lightmap"); 1 otherwise.
  double lightmap_scale = 1.0;
  int line = 0;  // line of the [[object]] table in the scene file, for errors
  // An object of a level file (level_file.h): the node of `mesh` it is, and the node's parts it
  // takes (empty: all; a node's emissive parts are lights). -1: every node of the file is this
  // one object. `transform` applies after the node's world transform.
  int node = -1;
  std::vector<std::uint32_t> parts;
};

// A polygon is a planar convex triangle or quad, a part of a mesh light; a mesh light (an
// emissive mesh of a level that is no planar rectangle or disc) is its triangles, baked as
// polygons (make_lights, scene/lights.h): every method bakes polygons, and a mesh light's
// outputs are its parts' combined by the one rule of methods/light_mix.h.
// A sky (scene/sky.h) is light from every direction at infinity, uniform or an environment map;
// like a mesh light it is baked as polygon parts (make_lights), a sphere of them far away.
enum class LightShape { rectangle, disk, sphere, polygon, mesh, sky };

// A point light (a sphere light of radius 0 in a scene file, a level's point and spot lights) is
// baked as a sphere of this radius, for every method: its penumbra, 10⁻⁵ m times a blocker's
// distance to the receiver over its distance to the light, is far below any texel, and its
// unoccluded irradiance is the point's, Φ cos θ / (4π d²), exactly wherever the sphere lies wholly
// above a texel's horizon (a sphere's closed form does not depend on its radius there).
inline constexpr double kPointLightRadius = 1e-5;

// A scene file's spot: the part of its cone over which it fades when `blend` is left out
// (Blender's default spot blend).
inline constexpr double kSpotBlend = 0.15;

// The polygons a sky is baked as unless its light says otherwise (scene/sky.h): an icosahedron's
// 20 faces split by flux up to this many (exact for a uniform sky at any number).
inline constexpr int kSkyParts = 128;

struct LightDesc {
  std::string name;
  LightShape shape = LightShape::rectangle;
  Vec3 position = Vec3::Zero();   // centre, metres
  Vec3 normal = Vec3(0, 0, -1);   // unit; the side it emits into (rectangle, disk)
  Vec3 up = Vec3(0, 1, 0);        // unit, made orthogonal to normal by the reader; height axis
  double width = 0;               // rectangle only, across up; metres
  double height = 0;              // rectangle only; metres
  double radius = 0;              // disk and sphere; metres (kPointLightRadius for a point)
  Vec3 color = Vec3(1, 1, 1);     // per-channel scale of the emitted power
  double power = 0;               // watts (for colour (1,1,1) and a white texture)
  std::filesystem::path texture;  // emission image over a rectangle or disk, a sky's map; resolved
  // The light's reach, metres from its centre (KHR_lights_punctual's `range`): inside it the
  // light's irradiance is windowed by clamp(1 − (d/range)⁴, 0, 1), glTF's recommended falloff
  // (Light::range_factor); at and beyond it the light adds nothing, and no method spends work on
  // it there. Infinite: it reaches everywhere (suns, skies and mesh lights always do).
  double range = std::numeric_limits<double>::infinity();
  // The shadow mask's reach (metres from the light's centre): beyond it the light's channel may
  // be given to another light (lightmaps/shadowmask.h). The scene reader sets it to `range`
  // where it is not given; infinite: wherever the light reaches.
  double shadowmask_range = std::numeric_limits<double>::infinity();
  // A spot (a sphere light imported from a level's spot light): the unit axis it shines along and
  // its cone's inner and outer half-angles, radians; spot_outer 0: no cone. Its unoccluded
  // irradiance falls off between the two as glTF's KHR_lights_punctual says (Light::spot_factor).
  Vec3 spot_axis = Vec3::Zero();
  double spot_inner = 0, spot_outer = 0;
  // A sun (a disk far away, sun_light.h): its angular diameter, degrees; 0 for other lights.
  double sun_angle_deg = 0;
  // A polygon's three or four corners, or a mesh light's triangles (three corners each), world
  // metres, counter-clockwise seen from the side they emit into (a mesh light's `position` is its
  // area-weighted centroid, `normal` and `up` unused). Empty for other shapes.
  std::vector<Vec3> corners;
  // A sky: radiance color · sky_strength W/m²/sr (Blender's Background colour and Strength),
  // times its map (`texture`, equirectangular) where it has one, the map turned by
  // sky_rotation_deg about +Z; baked as up to sky_parts polygons (scene/sky.h) on the sphere of
  // `radius` metres about `position`, which the bake places for the scene (place_sky).
  double sky_strength = 1;
  double sky_rotation_deg = 0;
  int sky_parts = kSkyParts;
  // An analytic sky in place of a map where sky_turbidity > 0: Preetham's clear sky of that
  // turbidity (scene/sky_models.h) around a sun whose light travels along sky_sun_direction
  // (unit, world), the direction of the sun light named sky_sun where it names one (set when the
  // scene is loaded).
  double sky_turbidity = 0;
  std::string sky_sun;
  Vec3 sky_sun_direction = Vec3::Zero();
  int line = 0;
};

// How a lightmap's values are stored in a file (lightmaps/encodings.h, docs/cli.md).
enum class Encoding {
  linear_exr,  // 32-bit float OpenEXR, linear
  half_exr,    // 16-bit float OpenEXR, linear
  png,         // 8-bit PNG, linear, value = byte / 255 · scale
  rgbm_png     // 8-bit RGBA PNG, RGBM as Unity decodes it: value = 34.49 · (A/255)^2.2 · RGB/255
};

// [output] atlas: receivers packed into shared square textures (texels/atlas_packing.h).
struct AtlasSettings {
  int size = 2048;  // texels per side of an atlas
  int padding = 2;  // texels around each receiver's rectangle that only it fills
};

// The [output] table: what files a bake writes beside manifest.json.
struct OutputSettings {
  Encoding encoding = Encoding::linear_exr;  // the lightmaps and the per-light images
  bool per_light = false;   // <object>.<light>.<ext>: each light's own V (or H0·V)
  bool shadowmask = false;  // <object>.shadowmask.<ext>: up to four lights' V in R, G, B, A
  Encoding shadowmask_encoding = Encoding::png;  // png, linear-exr or half-exr
  std::optional<AtlasSettings> atlas;            // receivers packed into atlases
  bool gltf = false;                             // scene.glb with every receiver, lightmap bound
};

// A [bake] key the scene file sets, and its line: keys the chosen method does not read are
// reported as ignored (pipeline/bake.cpp).
struct SettingGiven {
  std::string key;
  int line = 0;
};

struct Scene {
  std::filesystem::path file;  // the scene file, as given
  BakeSettings bake;
  OutputSettings output;
  std::vector<SettingGiven> bake_keys;  // in file order
  std::vector<ObjectDesc> objects;
  std::vector<LightDesc> lights;
  std::vector<std::string> warnings;  // what reading it noticed (a level's renamed nodes, ...)
};

// Reads and validates a scene file. Every problem is an Error naming the file, the line, the item
// and what is wrong; unknown keys are errors, not ignored. A file that is not .toml is a level
// (level_file.h), baked alone with the default settings.
// `need_lights` false: a scene without lights is no error (an ambient-occlusion bake's, which the
// command line may ask for on a file that says nothing of it).
// `methods`: the method names and keys a [bake] table may give (methods/method.h has
// load_scene(file), with this build's).
Expected<Scene> load_scene(const std::filesystem::path& file, const MethodVocabulary& methods,
                           bool need_lights = true);

// Quantity "ambient-occlusion" is baked by method "ambient-occlusion" and that method bakes only
// it: makes the two agree where one of them was left at its default (`quantity_given`,
// `method_given`: whether the scene or command line set them), else an error "<where>: ..."
// naming both.
// `ao_method`: the method that alone bakes ambient occlusion (MethodVocabulary).
Status pair_quantity_and_method(BakeSettings& bake, const std::string& ao_method,
                                bool quantity_given, bool method_given, const std::string& where);

// "file:line: object 'name'", where messages about an object start; "file: object 'name'" for an
// object of a level baked alone (line 0: no scene file line stands for it).
std::string object_location(const std::filesystem::path& scene_file, const ObjectDesc& obj);

// Builds an object's transform from the optional keys: scale, then rotation about X, then Y,
// then Z (degrees; Blender's "XYZ Euler"), then translation.
Affine3 object_transform(const Vec3& translate, const Vec3& rotate_deg, const Vec3& scale);

const char* to_string(Quantity q);
const char* to_string(LightShape s);
const char* to_string(Encoding e);  // as the scene file writes it: "linear-exr", ...
// An encoding as the scene file and the CLI name it, or nullopt.
std::optional<Encoding> parse_encoding(std::string_view text);

}  // namespace sb
