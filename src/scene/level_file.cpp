// Levels (level_file.h): a mesh file's nodes as objects, its emissive meshes and its
// KHR_lights_punctual lights as lights.
#include "scene/level_file.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "scene/file_nodes.h"
#include "scene/lights.h"
#include "scene/mesh_reader.h"
#include "scene/sun_light.h"

namespace sb {

namespace fs = std::filesystem;

namespace {

// Lumens per watt: KHR_lights_punctual's candela and lux to the watts and W/m² of the scene
// format, as Blender's glTF exporter and importer convert (PBR_WATTS_TO_LUMENS).
constexpr double kLumensPerWatt = 683;

std::string lower_extension(const fs::path& file) {
  std::string ext = file.extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

// The glTF document of a .gltf or .glb file (the JSON chunk of a binary one), or null when the
// file is not glTF or cannot be parsed (Assimp has read it by then, so it is well formed).
nlohmann::json gltf_document(const fs::path& file) {
  const std::string ext = lower_extension(file);
  if (ext != ".gltf" && ext != ".glb") return nullptr;
  std::ifstream in(file, std::ios::binary);
  if (ext == ".gltf") return nlohmann::json::parse(in, nullptr, false);
  // A binary glTF: its header (magic, version, length), then the first chunk's length and type
  // ("JSON") and the JSON itself; the binary chunk after it is not read again.
  std::uint32_t header[5] = {};
  if (!in.read(reinterpret_cast<char*>(header), sizeof header) || header[4] != 0x4E4F534A ||
      header[3] > header[2])
    return nullptr;
  std::string json(header[3], '\0');
  if (!in.read(json.data(), std::streamsize(json.size()))) return nullptr;
  return nlohmann::json::parse(json, nullptr, false);
}

// Per material of the file, KHR_materials_emissive_strength's factor (1 where absent). Assimp
// 5.2 does not read that extension; it keeps glTF's materials in their order.
std::vector<double> emissive_strengths(const nlohmann::json& gltf, std::size_t count) {
  std::vector<double> strength(count, 1.0);
  if (!gltf.is_object() || !gltf.contains("materials") || !gltf["materials"].is_array())
    return strength;
  const auto& materials = gltf["materials"];
  for (std::size_t i = 0; i < std::min(count, materials.size()); ++i) {
    const auto* value = &materials[i];
    for (const char* key : {"extensions", "KHR_materials_emissive_strength", "emissiveStrength"}) {
      if (!value->is_object() || !value->contains(key)) {
        value = nullptr;
        break;
      }
      value = &(*value)[key];
    }
    if (value && value->is_number()) strength[i] = value->get<double>();
  }
  return strength;
}

// Per node name, the `range` of the KHR_lights_punctual light the node holds, where it gives one
// (metres in the file's frame). Assimp 5.2 keeps it only as a node's metadata, so it is read
// here from the document, as the emissive strengths are. A range that is not a number is kept as
// NaN, for the light's reader to refuse.
std::map<std::string, double> gltf_light_ranges(const nlohmann::json& gltf) {
  std::map<std::string, double> ranges;
  if (!gltf.is_object() || !gltf.contains("nodes") || !gltf["nodes"].is_array()) return ranges;
  const nlohmann::json* lights = nullptr;
  if (gltf.contains("extensions") && gltf["extensions"].is_object()) {
    const auto& ext = gltf["extensions"];
    if (ext.contains("KHR_lights_punctual") && ext["KHR_lights_punctual"].is_object() &&
        ext["KHR_lights_punctual"].contains("lights") &&
        ext["KHR_lights_punctual"]["lights"].is_array())
      lights = &ext["KHR_lights_punctual"]["lights"];
  }
  if (!lights) return ranges;
  for (const auto& node : gltf["nodes"]) {
    if (!node.is_object() || !node.contains("name") || !node["name"].is_string() ||
        !node.contains("extensions") || !node["extensions"].is_object())
      continue;
    const auto& ext = node["extensions"];
    if (!ext.contains("KHR_lights_punctual") || !ext["KHR_lights_punctual"].is_object()) continue;
    const auto& index = ext["KHR_lights_punctual"]["light"];
    if (!index.is_number_unsigned() || index.get<std::size_t>() >= lights->size()) continue;
    const auto& light = (*lights)[index.get<std::size_t>()];
    if (!light.is_object() || !light.contains("range")) continue;
    ranges[node["name"].get<std::string>()] = light["range"].is_number()
                                                  ? light["range"].get<double>()
                                                  : std::numeric_limits<double>::quiet_NaN();
  }
  return ranges;
}

// A node's name as an object or light name: characters a file name cannot hold become '_'.
std::string safe_name(const std::string& name) {
  std::string out;
  for (char c : name) out += is_file_name_char(c) ? c : '_';
  if (out.empty()) out = "node";
  if (out.front() == '.') out.front() = '_';
  return out;
}

// Unique names for the nodes in `wanted` (indices into file.nodes): the node's own name, the
// path of its parents (below the root) in front where two share it, and "-2", "-3", ... where
// that still repeats (a warning each).
std::map<std::size_t, std::string> unique_names(const RawMeshFile& file,
                                                const std::vector<std::size_t>& wanted,
                                                const std::string& where,
                                                std::vector<std::string>& warnings) {
  std::map<std::string, int> uses;
  for (std::size_t n : wanted) ++uses[safe_name(file.nodes[n].name)];
  std::map<std::size_t, std::string> names;
  std::set<std::string> taken;
  for (std::size_t n : wanted) {
    std::string name = safe_name(file.nodes[n].name);
    if (uses[name] > 1) {
      for (std::int32_t p = file.nodes[n].parent; p > 0; p = file.nodes[std::size_t(p)].parent)
        name = safe_name(file.nodes[std::size_t(p)].name) + "-" + name;
    }
    if (!taken.insert(name).second) {
      std::string numbered;
      for (int k = 2; !taken.insert(numbered = fmt::format("{}-{}", name, k)).second; ++k) {
      }
      warnings.push_back(
          fmt::format("{}: node '{}': another node has the same name and parents; "
                      "named '{}'",
                      where, file.nodes[n].name, numbered));
      name = numbered;
    }
    names[n] = name;
  }
  return names;
}

// An emissive part's triangles in world space, front side first (glTF's counter-clockwise).
std::vector<Vec3> world_triangles(const RawMeshPart& part, const Affine3& transform) {
  std::vector<Vec3> corners;
  const bool mirrors = transform.linear().determinant() < 0;
  for (std::size_t f = 0; f + 2 < part.triangles.size(); f += 3) {
    Vec3 p[3];
    for (int k = 0; k < 3; ++k) {
      const float* v = &part.positions[3 * part.triangles[f + std::size_t(k)]];
      p[k] = transform * Vec3(v[0], v[1], v[2]);
    }
    if (mirrors) std::swap(p[1], p[2]);
    corners.insert(corners.end(), {p[0], p[1], p[2]});
  }
  return corners;
}

// The light an emissive part's triangles make, if they are a planar rectangle or disc: shape,
// centre, normal (the front side), up, size. nullopt for any other shape.
std::optional<LightDesc> planar_light(const std::vector<Vec3>& corners) {
  Vec3 normal_sum = Vec3::Zero(), centroid = Vec3::Zero();
  double area = 0;
  Bounds3 bounds;
  for (std::size_t i = 0; i + 2 < corners.size(); i += 3) {
    const Vec3 cross = (corners[i + 1] - corners[i]).cross(corners[i + 2] - corners[i]);
    normal_sum += cross;
    area += 0.5 * cross.norm();
    centroid += 0.5 * cross.norm() * (corners[i] + corners[i + 1] + corners[i + 2]) / 3.0;
    for (int k = 0; k < 3; ++k) bounds.extend(corners[i + std::size_t(k)]);
  }
  if (!(area > 0) || normal_sum.norm() < 0.999 * 2 * area) return std::nullopt;  // not one plane
  const Vec3 n = normal_sum.normalized();
  centroid /= area;
  const double size = bounds.diagonal();
  for (const Vec3& p : corners)
    if (std::abs((p - centroid).dot(n)) > 1e-4 * size) return std::nullopt;

  LightDesc light;
  light.normal = n;
  // A rectangle: some triangle edge is a side, and the box along it has the triangles' area.
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i + 1 < corners.size(); ++i) {
    Vec3 u = corners[i + 1] - corners[i];
    u -= u.dot(n) * n;
    if (u.norm() < 1e-6 * size) continue;
    u.normalize();
    const Vec3 v = n.cross(u);
    double u0 = 1e300, u1 = -1e300, v0 = 1e300, v1 = -1e300;
    for (const Vec3& p : corners) {
      u0 = std::min(u0, (p - centroid).dot(u));
      u1 = std::max(u1, (p - centroid).dot(u));
      v0 = std::min(v0, (p - centroid).dot(v));
      v1 = std::max(v1, (p - centroid).dot(v));
    }
    const double box = (u1 - u0) * (v1 - v0);
    if (box < best && std::abs(box - area) <= 1e-3 * area) {
      best = box;
      light.shape = LightShape::rectangle;
      light.position = centroid + 0.5 * (u0 + u1) * u + 0.5 * (v0 + v1) * v;
      light.up = v;  // right = up × normal = u
      light.width = u1 - u0;
      light.height = v1 - v0;
    }
  }
  if (std::isfinite(best)) return light;
  // A disc: a polygon of at least 16 sides about its centroid holds more than 97 % of the
  // circle through its farthest corner; it becomes a disk of its own area.
  double reach = 0;
  for (const Vec3& p : corners) reach = std::max(reach, (p - centroid).norm());
  if (area < 0.97 * std::numbers::pi * reach * reach) return std::nullopt;
  light.shape = LightShape::disk;
  light.position = centroid;
  light.radius = std::sqrt(area / std::numbers::pi);
  const Vec3 y = std::abs(n.y()) < 0.999 ? Vec3::UnitY() : Vec3::UnitZ();
  light.up = (y - y.dot(n) * n).normalized();
  return light;
}

// The light an emissive part that is no rectangle or disc makes: a mesh light of its triangles
// (those of some area, front side counter-clockwise), at their area-weighted centroid; nullopt
// when they have no area.
std::optional<LightDesc> mesh_light(std::vector<Vec3> corners) {
  LightDesc light;
  light.shape = LightShape::mesh;
  Vec3 centroid = Vec3::Zero();
  double area = 0;
  for (std::size_t i = 0; i + 2 < corners.size(); i += 3) {
    const double a = 0.5 * (corners[i + 1] - corners[i]).cross(corners[i + 2] - corners[i]).norm();
    if (!(a > 0)) continue;
    light.corners.insert(light.corners.end(), {corners[i], corners[i + 1], corners[i + 2]});
    centroid += a * (corners[i] + corners[i + 1] + corners[i + 2]) / 3.0;
    area += a;
  }
  if (!(area > 0)) return std::nullopt;
  light.position = centroid / area;
  return light;
}

// Bytes a level's meshes take once built, per triangle placed: an allowance for OpenMesh's
// half-edges and attributes, the ray tracer's copy and the shafts' bounds (not measured; the
// bake's own memory check, which counts its lightmaps, is what refuses real levels).
constexpr double kBytesPerPlacedTriangle = 400;

// Emission per material (radiance, W/(m²·sr), per channel): its emissive colour times its
// KHR_materials_emissive_strength factor.
std::vector<Vec3> material_emission(const RawMeshFile& raw, const std::vector<double>& strength) {
  std::vector<Vec3> emission(raw.materials.size(), Vec3::Zero());
  for (std::size_t m = 0; m < raw.materials.size(); ++m) {
    const auto& e = raw.materials[m].emissive;
    emission[m] = Vec3(e[0], e[1], e[2]) * strength[m];
  }
  return emission;
}

// The steps of import_level, sharing the file's contents, its placement and what it makes.
struct LevelImport {
  const fs::path& file;
  const std::string& where;
  const Affine3& placement;
  int line;
  const RawMeshFile& raw;
  const std::vector<Affine3>& world;            // per node, its transform in the file
  const nlohmann::json& gltf;                   // the glTF document, or null for another format
  const std::map<std::string, double>& ranges;  // per node name, its light's range
  const std::vector<Vec3>& emission;            // per material
  LevelContents level;
  std::set<std::string> light_names;  // those given so far

  Error fail(const std::string& node, const std::string& problem) const {
    return scene_error(fmt::format("{}: node '{}': {}", where, node, problem));
  }
  Status find_object_nodes(const ImportLimits& limits, std::vector<std::size_t>& object_nodes);
  void add_objects(const std::vector<std::size_t>& object_nodes);
  Bounds3 level_bounds(const std::vector<std::size_t>& object_nodes) const;
  std::string light_name(const std::string& node);
  void add_emissive_lights();
  Status add_punctual_light(const RawLight& raw_light, const Bounds3& scene_bounds);
  Status add_sun(const RawLight& raw_light, const Affine3& transform, const Vec3& color,
                 const Bounds3& scene_bounds);
  Status add_point_light(const RawLight& raw_light, const Affine3& transform, const Vec3& color,
                         const Vec3& position);
};

// The nodes with some non-emissive part, which become objects. A negative or non-finite emission
// is an error naming the first node that uses it; so are more placed triangles than the bake's
// memory allows.
Status LevelImport::find_object_nodes(const ImportLimits& limits,
                                      std::vector<std::size_t>& object_nodes) {
  double placed_triangles = 0;
  for (std::size_t n = 0; n < raw.nodes.size(); ++n) {
    bool surface = false;
    for (std::uint32_t p : raw.nodes[n].parts) {
      const RawMeshPart& part = raw.parts[p];
      const Vec3 e = part.material < emission.size() ? emission[part.material] : Vec3::Zero();
      if (!e.allFinite() || (e.array() < 0).any()) {
        return fail(raw.nodes[n].name,
                    fmt::format("material '{}' has a negative or non-finite emission ({}, {}, {})",
                                raw.materials[part.material].name, e.x(), e.y(), e.z()));
      }
      surface = surface || !(e.maxCoeff() > 0);
      placed_triangles += double(part.triangles.size() / 3);
    }
    if (surface) object_nodes.push_back(n);
  }
  // 100,000 instances of a mesh are cheap in the file and not in the bake: refused here with
  // their cost rather than part-way through building them.
  const double bytes = placed_triangles * kBytesPerPlacedTriangle;
  if (limits.max_memory > 0 && bytes > double(limits.max_memory)) {
    return scene_error(fmt::format(
        "{}: its {} nodes place {:.0f} triangles, about {:.1f} GiB once built, more than the "
        "{:.1f} GiB the bake may use; bake fewer instances or raise max_memory (--max-memory)",
        where, raw.nodes.size(), placed_triangles, bytes / double(1ull << 30),
        double(limits.max_memory) / double(1ull << 30)));
  }
  return Ok{};
}

// Objects: a node's non-emissive parts.
void LevelImport::add_objects(const std::vector<std::size_t>& object_nodes) {
  const auto names = unique_names(raw, object_nodes, where, level.warnings);
  for (std::size_t n : object_nodes) {
    ObjectDesc obj;
    obj.name = names.at(n);
    obj.mesh = file;
    obj.node = int(n);
    obj.transform = placement;
    obj.line = line;
    int channels = kMaxUvChannels;
    for (std::uint32_t p : raw.nodes[n].parts) {
      const RawMeshPart& part = raw.parts[p];
      if (part.material < emission.size() && emission[part.material].maxCoeff() > 0) continue;
      obj.parts.push_back(p);
      channels = std::min(channels, part.uv_channel_count());
    }
    if (obj.parts.size() == raw.nodes[n].parts.size()) obj.parts.clear();
    // The second UV set is the lightmap's by every engine's convention; without one, the bake
    // makes lightmap UVs (channel 0, if any, stays the texture UVs a glTF of the bake carries).
    obj.auto_uv = channels < 2;
    obj.uv_channel = obj.auto_uv ? 0 : 1;
    level.objects.push_back(std::move(obj));
  }
}

// The level's extent, for where a sun is put.
Bounds3 LevelImport::level_bounds(const std::vector<std::size_t>& object_nodes) const {
  Bounds3 scene_bounds;
  for (std::size_t n : object_nodes) {
    const Affine3 node_transform = placement * world[n];
    for (std::uint32_t p : raw.nodes[n].parts) {
      const std::vector<float>& positions = raw.parts[p].positions;
      for (std::size_t i = 0; i + 2 < positions.size(); i += 3)
        scene_bounds.extend(node_transform *
                            Vec3(positions[i], positions[i + 1], positions[i + 2]));
    }
  }
  if (scene_bounds.empty()) scene_bounds.extend(Vec3::Zero());
  return scene_bounds;
}

// A light's name from its node's: file-name-safe, and numbered where an earlier light has it.
std::string LevelImport::light_name(const std::string& node) {
  std::string name = safe_name(node);
  for (int k = 2; !light_names.insert(name).second; ++k)
    name = fmt::format("{}-{}", safe_name(node), k);
  return name;
}

// Lights of the emissive parts: rectangles, discs and other meshes (a warning for each left out).
void LevelImport::add_emissive_lights() {
  for (std::size_t n = 0; n < raw.nodes.size(); ++n) {
    for (std::uint32_t p : raw.nodes[n].parts) {
      const RawMeshPart& part = raw.parts[p];
      if (part.material >= emission.size() || !(emission[part.material].maxCoeff() > 0)) continue;
      const std::string& node = raw.nodes[n].name;
      std::vector<Vec3> triangles = world_triangles(part, placement * world[n]);
      std::optional<LightDesc> shape = planar_light(triangles);
      if (!shape) shape = mesh_light(std::move(triangles));
      if (!shape) {
        level.warnings.push_back(fmt::format(
            "{}: node '{}': its emissive material '{}' is on a mesh of no area; it is left out",
            where, node, raw.materials[part.material].name));
        continue;
      }
      if (shape->corners.size() / 3 > kMaxMeshLightTriangles) {
        level.warnings.push_back(fmt::format(
            "{}: node '{}': its emissive material '{}' is on a mesh of {} triangles, more than "
            "the {} a mesh light may have (each of its triangles or quads is baked as a light); it "
            "is left out",
            where, node, raw.materials[part.material].name, shape->corners.size() / 3,
            kMaxMeshLightTriangles));
        continue;
      }
      LightDesc light = *shape;
      light.name = light_name(node);
      light.line = line;
      const Vec3& e = emission[part.material];
      light.color = e / e.maxCoeff();
      light.power = std::numbers::pi * e.maxCoeff() * Light(light).area();
      level.lights.push_back(std::move(light));
    }
  }
}

// One of the file's punctual lights, placed by its node: a sun, a point or spot light, or a
// warning where it is of a kind not read; none where it is switched off.
Status LevelImport::add_punctual_light(const RawLight& raw_light, const Bounds3& scene_bounds) {
  const auto node = std::find_if(raw.nodes.begin(), raw.nodes.end(),
                                 [&](const RawNode& n) { return n.name == raw_light.name; });
  const Affine3 transform =
      placement * (node == raw.nodes.end() ? Affine3::Identity()
                                           : world[std::size_t(node - raw.nodes.begin())]);
  const Vec3 color(raw_light.color[0], raw_light.color[1], raw_light.color[2]);
  const Vec3 position =
      transform * Vec3(raw_light.position[0], raw_light.position[1], raw_light.position[2]);
  if (!color.allFinite() || (color.array() < 0).any() || !position.allFinite())
    return fail(raw_light.name, "the light has a negative or non-finite intensity or position");
  if (raw_light.type != RawLight::point && raw_light.type != RawLight::spot &&
      raw_light.type != RawLight::directional) {
    level.warnings.push_back(
        fmt::format("{}: node '{}': area and ambient lights are not read yet; it is left out",
                    where, raw_light.name));
    return Ok{};
  }
  if (!(color.maxCoeff() > 0)) return Ok{};  // a light switched off
  if (raw_light.type == RawLight::directional)
    return add_sun(raw_light, transform, color, scene_bounds);
  return add_point_light(raw_light, transform, color, position);
}

// A directional light as a sun over the level's extent.
Status LevelImport::add_sun(const RawLight& raw_light, const Affine3& transform, const Vec3& color,
                            const Bounds3& scene_bounds) {
  const Vec3 direction = transform.linear() * Vec3(raw_light.direction[0], raw_light.direction[1],
                                                   raw_light.direction[2]);
  if (!direction.allFinite() || !(direction.norm() > 0))
    return fail(raw_light.name, "the sun has a zero or non-finite direction");
  // glTF's sun is lux; FBX's (as Blender writes it) W/m².
  const double irradiance = gltf.is_object() ? color.maxCoeff() / kLumensPerWatt : color.maxCoeff();
  LightDesc sun = sun_light(direction.normalized(), kSunAngleDeg, irradiance, scene_bounds);
  sun.name = light_name(raw_light.name);
  sun.color = color / color.maxCoeff();
  sun.line = line;
  level.lights.push_back(std::move(sun));
  return Ok{};
}

// A point or spot light as a point light (a spot keeping its cone), with its glTF range if any.
Status LevelImport::add_point_light(const RawLight& raw_light, const Affine3& transform,
                                    const Vec3& color, const Vec3& position) {
  LightDesc light;
  if (raw_light.type == RawLight::spot) {
    const Vec3 axis = transform.linear() *
                      Vec3(raw_light.direction[0], raw_light.direction[1], raw_light.direction[2]);
    // glTF's cone angles are half-angles; Assimp gives FBX's as the whole cone.
    const double half = gltf.is_object() ? 1.0 : 0.5;
    light.spot_inner = half * raw_light.inner_cone;
    light.spot_outer = half * raw_light.outer_cone;
    if (!axis.allFinite() || !(axis.norm() > 0) || !std::isfinite(light.spot_inner) ||
        !(light.spot_outer > 0) || !(light.spot_outer < std::numbers::pi))
      return fail(raw_light.name, "the spot light has a zero or non-finite direction or cone");
    light.spot_axis = axis.normalized();
    light.spot_inner = std::clamp(light.spot_inner, 0.0, light.spot_outer);
  }
  light.name = light_name(raw_light.name);
  light.shape = LightShape::sphere;
  light.position = position;
  light.radius = kPointLightRadius;  // a point, as glTF's are
  light.color = color / color.maxCoeff();
  // glTF's intensity is candela; other formats' (FBX as Blender writes it) is the light's
  // watts.
  light.power = gltf.is_object() ? 4 * std::numbers::pi * color.maxCoeff() / kLumensPerWatt
                                 : color.maxCoeff();
  light.line = line;
  if (const auto range = ranges.find(raw_light.name); range != ranges.end()) {
    // glTF's "range": metres in the file's frame, scaled as the placement scales the level
    // (its largest axis scale, so that a light reaches at least as far as the file says).
    const double scale = transform.linear().colwise().norm().maxCoeff();
    if (!std::isfinite(range->second) || !(range->second > 0))
      return fail(raw_light.name,
                  fmt::format("the light's KHR_lights_punctual range is {}; it must be a "
                              "finite number > 0 (metres), or left out to reach everywhere",
                              range->second));
    light.range = range->second * scale;
    light.shadowmask_range = light.range;
  }
  level.lights.push_back(std::move(light));
  return Ok{};
}

}  // namespace

bool is_level_file(const fs::path& file) { return lower_extension(file) != ".toml"; }

Expected<LevelContents> import_level(const fs::path& file, const Affine3& placement, int line,
                                     const ImportLimits& limits) {
  const std::string where = file.string();
  auto raw = read_checked_mesh_file(file, limits);
  if (!raw) return raw.error();
  const std::vector<Affine3> world = node_world_transforms(*raw);
  const nlohmann::json gltf = gltf_document(file);
  const std::vector<double> strength = emissive_strengths(gltf, raw->materials.size());
  const std::map<std::string, double> ranges = gltf_light_ranges(gltf);
  const std::vector<Vec3> emission = material_emission(*raw, strength);
  LevelImport importer{file, where, placement, line, *raw, world, gltf, ranges, emission, {}, {}};

  std::vector<std::size_t> object_nodes;
  if (Status found = importer.find_object_nodes(limits, object_nodes); !found) return found.error();
  importer.add_objects(object_nodes);
  const Bounds3 scene_bounds = importer.level_bounds(object_nodes);
  // Lights: emissive rectangles, discs and other meshes, then the file's punctual lights.
  importer.add_emissive_lights();
  for (const RawLight& raw_light : raw->lights)
    if (Status added = importer.add_punctual_light(raw_light, scene_bounds); !added)
      return added.error();
  return std::move(importer.level);
}

Expected<Scene> load_level_scene(const fs::path& file, bool need_lights) {
  Scene scene;
  scene.file = file;
  auto level = import_level(file, Affine3::Identity(), 0);
  if (!level) return level.error();
  scene.objects = std::move(level->objects);
  scene.lights = std::move(level->lights);
  scene.warnings = std::move(level->warnings);
  if (scene.objects.empty())
    return scene_error(file.string() + ": no node places a mesh, so there is nothing to bake");
  if (scene.lights.empty() && need_lights) {
    // What was left out is the reason more often than not: say how many, and the first.
    std::string left_out;
    if (!scene.warnings.empty())
      left_out = fmt::format(" ({} warning(s) while reading it, the first: {})",
                             scene.warnings.size(), scene.warnings.front());
    return scene_error(file.string() +
                       ": holds no light shadowbake reads (KHR_lights_punctual point, spot or "
                       "directional lights, or emissive meshes); add one, bake it from a "
                       "scene file that imports it and adds [[light]] tables, or bake its "
                       "ambient occlusion (--quantity ambient-occlusion)" +
                       left_out);
  }
  if (std::none_of(scene.objects.begin(), scene.objects.end(),
                   [](const ObjectDesc& o) { return o.receiver; }))
    return scene_error(file.string() + ": no node has lightmap UVs, so there is nothing to bake");
  return scene;
}

}  // namespace sb
