// Incremental bakes' keys and cache (bake_cache.h).
#include "pipeline/bake_cache.h"

#include <fmt/format.h>
#include <tbb/parallel_for.h>
#include <xxhash.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <map>
#include <set>

#include "formats/settings_json.h"
#include "formats/shard_files.h"
#include "occluders/shaft_culling.h"
#include "pipeline/bake_stages.h"
#include "source_hash.h"  // generated at build time (CMakeLists.txt, script mode)

namespace sb {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

namespace {

// A receiver's shafts are tested from the boxes of its parts in a grid of this many cells a side.
constexpr int kCells = 4;

// An XXH3-128 hash fed field by field; each variable-length field is preceded by its length.
class Hash {
 public:
  Hash() : state_(XXH3_createState()) { XXH3_128bits_reset(state_); }
  ~Hash() { XXH3_freeState(state_); }
  Hash(const Hash&) = delete;
  Hash& operator=(const Hash&) = delete;

  void bytes(const void* data, std::size_t size) { XXH3_128bits_update(state_, data, size); }
  void text(const std::string& s) {
    number(double(s.size()));
    bytes(s.data(), s.size());
  }
  void number(double v) { bytes(&v, sizeof v); }
  void vec(const Vec3& v) {
    for (int k = 0; k < 3; ++k) number(v[k]);
  }
  std::string hex() const {
    const XXH128_hash_t h = XXH3_128bits_digest(state_);
    return fmt::format("{:016x}{:016x}", h.high64, h.low64);
  }

 private:
  XXH3_state_t* state_;
};

// A mesh as the bake reads it.
std::string mesh_hash(const Mesh& m) {
  Hash h;
  h.text(m.name);
  const TriMesh& mesh = m.mesh;
  h.number(double(mesh.n_vertices()));
  for (const auto v : mesh.vertices()) {
    const auto& p = mesh.point(v);
    h.bytes(p.data(), sizeof(p[0]) * 3);
    if (mesh.has_vertex_normals()) {
      const auto& n = mesh.normal(v);
      h.bytes(n.data(), sizeof(n[0]) * 3);
    }
    if (mesh.has_vertex_texcoords2D()) {
      const auto& t = mesh.texcoord2D(v);
      h.bytes(t.data(), sizeof(t[0]) * 2);
    }
  }
  h.number(double(mesh.n_faces()));
  for (const auto f : mesh.faces())
    for (const auto v : mesh.fv_range(f)) {
      const int index = v.idx();
      h.bytes(&index, sizeof index);
    }
  h.number(m.has_uv ? 1 : 0);
  h.number(double(m.texture_uv.size()));
  for (const Vec2& t : m.texture_uv) h.bytes(t.data(), sizeof(double) * 2);
  return h.hex();
}

// A file's bytes, for a light's texture.
Expected<std::string> file_hash(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return input_error(path.string() + ": cannot read the light's texture");
  Hash h;
  std::vector<char> buffer(1 << 16);
  while (in.read(buffer.data(), std::streamsize(buffer.size())) || in.gcount() > 0)
    h.bytes(buffer.data(), std::size_t(in.gcount()));
  return h.hex();
}

Bounds3 mesh_bounds(const Mesh& m) {
  Bounds3 box;
  for (const auto v : m.mesh.vertices()) {
    const auto& p = m.mesh.point(v);
    box.extend(Vec3(p[0], p[1], p[2]));
  }
  return box;
}

bool overlap(const Bounds3& a, const Bounds3& b) {
  return !a.empty() && !b.empty() && (a.lo.array() <= b.hi.array()).all() &&
         (b.lo.array() <= a.hi.array()).all();
}

// The cache's two files for a receiver, relative to the output folder.
std::string metadata_name(const std::string& receiver) {
  return (fs::path(kCacheFolder) / (receiver + ".json")).generic_string();
}
std::string data_name(const std::string& receiver) {
  return (fs::path(kCacheFolder) / (receiver + ".bin")).generic_string();
}

json key_json(const ReceiverKey& k) {
  return {{"settings", k.settings},
          {"receiver", k.receiver},
          {"lights", k.lights},
          {"blockers", k.blockers}};
}

// The hash that every receiver's key shares: the build, the settings and what is kept per light.
std::string settings_hash(const KeyInputs& in) {
  const Scene& scene = *in.scene;
  Hash h;
  h.text(SHADOWBAKE_VERSION);
  h.text(SHADOWBAKE_SOURCE_HASH);  // another build's code may give other values
  h.text(settings_to_json(scene.bake, scene.output).dump());
  h.number(in.keep_per_light.values ? 1 : 0);
  h.number(in.keep_per_light.visibility ? 1 : 0);
  h.number(double(scene.lights.size()));
  return h.hex();
}

// Each light's own hash, from its description and its texture's bytes; each texture is read once.
Expected<std::vector<std::string>> light_hashes(const std::vector<Light>& lights) {
  std::vector<std::string> hashes(lights.size());
  std::map<fs::path, std::string> textures;
  for (std::size_t l = 0; l < lights.size(); ++l) {
    const LightDesc& d = lights[l].desc();
    Hash h;
    h.number(double(l));
    h.number(double(lights[l].output()));
    h.text(d.name);
    h.number(double(int(d.shape)));
    h.vec(d.position), h.vec(d.normal), h.vec(d.up);
    h.number(d.width), h.number(d.height), h.number(d.radius);
    h.vec(d.color), h.number(d.power);
    h.number(d.shadowmask_range);
    h.number(d.range);
    h.vec(d.spot_axis), h.number(d.spot_inner), h.number(d.spot_outer);
    h.number(d.sun_angle_deg);
    h.number(double(d.corners.size()));
    for (const Vec3& c : d.corners) h.vec(c);
    h.number(d.sky_strength), h.number(d.sky_rotation_deg), h.number(double(d.sky_parts));
    h.number(d.sky_turbidity), h.vec(d.sky_sun_direction);
    h.text(d.texture.string());
    if (!d.texture.empty()) {
      auto found = textures.find(d.texture);
      if (found == textures.end()) {
        auto bytes = file_hash(d.texture);
        if (!bytes) return bytes.error();
        found = textures.emplace(d.texture, *bytes).first;
      }
      h.text(found->second);
    }
    hashes[l] = h.hex();
  }
  return hashes;
}

// The hashes of the lights and blockers, and the blockers' boxes, which all receivers share.
struct SharedHashes {
  std::vector<std::string> lights, blockers;
  std::vector<Bounds3> blocker_boxes;
};

// A receiver's own hash: its name, lightmap side, UV choice and mesh.
std::string receiver_hash(const ObjectDesc& obj, int side, const Mesh& mesh) {
  Hash h;
  h.text(obj.name);  // its sampling stream's key, too
  h.number(double(side));
  h.number(double(obj.uv_channel));
  h.number(obj.auto_uv ? 1 : 0);
  h.text(mesh_hash(mesh));
  return h.hex();
}

// A receiver's box, and the boxes of its parts from which its shafts are tested.
struct ReceiverBoxes {
  Bounds3 box;
  std::vector<Bounds3> parts;
};

// Its box, grown for the shadow origins lifted off the surface (texel_space.h), and the
// boxes of its triangles in each cell of a kCells³ grid over it (by centroid), grown alike:
// a floor's far end has shafts of its own.
ReceiverBoxes receiver_boxes(const Mesh& mesh) {
  Bounds3 box = mesh_bounds(mesh);
  const Vec3 grow = Vec3::Constant(1e-3 + 1e-2 * box.diagonal());
  std::vector<Bounds3> parts(std::size_t(kCells * kCells * kCells));
  const Vec3 extent = (box.hi - box.lo).cwiseMax(Vec3::Constant(1e-12));
  for (const auto f : mesh.mesh.faces()) {
    Bounds3 tri;
    for (const auto v : mesh.mesh.fv_range(f)) {
      const auto& p = mesh.mesh.point(v);
      tri.extend(Vec3(p[0], p[1], p[2]));
    }
    const Vec3 at = ((tri.centre() - box.lo).cwiseQuotient(extent) * kCells).cwiseMax(0.0);
    const auto cell = [&](int k) { return std::min(int(at[k]), kCells - 1); };
    parts[std::size_t((cell(2) * kCells + cell(1)) * kCells + cell(0))].extend(tri);
  }
  parts.erase(
      std::remove_if(parts.begin(), parts.end(), [](const Bounds3& b) { return b.empty(); }),
      parts.end());
  for (Bounds3& b : parts) b.lo -= grow, b.hi += grow;
  box.lo -= grow, box.hi += grow;
  return {box, std::move(parts)};
}

// Sets the key's hashes of the lights that may reach the receiver and of the blockers that may
// lie in its shafts; lists the reaching lights (Light::output) in `reaching` when it is given.
void hash_reach(const KeyInputs& in, const SharedHashes& shared, const ReceiverBoxes& boxes,
                ReceiverKey& key, std::vector<int>* reaching) {
  const Scene& scene = *in.scene;
  const std::vector<Light>& lights = *in.lights;
  const std::vector<const Mesh*>& blockers = *in.blockers;
  const bool ambient_occlusion = scene.bake.quantity == Quantity::ambient_occlusion;
  const bool local = in.local;
  const Bounds3& box = boxes.box;
  std::vector<std::uint8_t> blocker_in(blockers.size(), local ? 0 : 1);
  Hash lights_hash;
  if (!ambient_occlusion) {
    std::vector<std::uint32_t> candidates;
    for (std::size_t l = 0; l < lights.size(); ++l) {
      if (!lights[l].may_reach(box)) continue;
      lights_hash.text(shared.lights[l]);
      if (reaching) reaching->push_back(lights[l].output());
      if (!local) continue;
      for (const Bounds3& part : boxes.parts) {
        // Too many to list (or no culler): every blocker may be in the shafts.
        if (in.culler == nullptr ||
            (in.culler->tile_candidates(part, lights[l], std::size_t(1) << 22, candidates) &&
             candidates.empty())) {
          std::fill(blocker_in.begin(), blocker_in.end(), 1);
          break;
        }
        for (std::uint32_t t : candidates) blocker_in[std::size_t(in.culler->mesh_of(t))] = 1;
      }
    }
  } else if (local) {
    Bounds3 reach = box;
    reach.lo -= Vec3::Constant(scene.bake.ao_distance);
    reach.hi += Vec3::Constant(scene.bake.ao_distance);
    for (std::size_t b = 0; b < blockers.size(); ++b)
      blocker_in[b] = overlap(reach, shared.blocker_boxes[b]);
  }
  key.lights = lights_hash.hex();
  Hash blockers_hash;
  for (std::size_t b = 0; b < blockers.size(); ++b)
    if (blocker_in[b]) blockers_hash.text(shared.blockers[b]);
  key.blockers = blockers_hash.hex();
}

}  // namespace

Expected<std::vector<ReceiverKey>> receiver_keys(const KeyInputs& in,
                                                 const std::vector<std::size_t>& objects,
                                                 const std::vector<int>& sides,
                                                 std::vector<std::vector<int>>* reaching) {
  const Scene& scene = *in.scene;
  const std::vector<const Mesh*>& blockers = *in.blockers;
  const std::string settings = settings_hash(in);
  // Each light's and blocker's own hash, once.
  SharedHashes shared;
  auto lights = light_hashes(*in.lights);
  if (!lights) return lights.error();
  shared.lights = std::move(*lights);
  shared.blockers.resize(blockers.size());
  shared.blocker_boxes.resize(blockers.size());
  tbb::parallel_for(std::size_t(0), blockers.size(), [&](std::size_t b) {
    shared.blockers[b] = mesh_hash(*blockers[b]);
    shared.blocker_boxes[b] = mesh_bounds(*blockers[b]);
  });

  std::vector<ReceiverKey> keys(objects.size());
  if (reaching) reaching->assign(objects.size(), {});
  // Receivers in parallel: each key is its own.
  tbb::parallel_for(std::size_t(0), objects.size(), [&](std::size_t r) {
    const std::size_t object = objects[r];
    const Mesh& mesh = (*in.meshes)[object];
    ReceiverKey& key = keys[r];
    key.settings = settings;
    key.receiver = receiver_hash(scene.objects[object], sides[r], mesh);
    hash_reach(in, shared, receiver_boxes(mesh), key, reaching ? &(*reaching)[r] : nullptr);
  });
  return keys;
}

std::string key_change(const ReceiverKey& before, const ReceiverKey& now) {
  std::vector<std::string> parts;
  if (before.settings != now.settings) parts.push_back("the settings");
  if (before.receiver != now.receiver) parts.push_back("its mesh or lightmap");
  if (before.lights != now.lights) parts.push_back("the lights that may reach it");
  if (before.blockers != now.blockers) parts.push_back("the blockers in its shafts");
  return fmt::format("{}", fmt::join(parts, ", "));
}

std::optional<CachedReceiver> find_cached(const fs::path& output_dir, const std::string& name) {
  CachedReceiver entry;
  entry.metadata = output_dir / metadata_name(name);
  entry.data = output_dir / data_name(name);
  std::ifstream in(entry.metadata);
  if (!in) return std::nullopt;
  const json j = json::parse(in, nullptr, false);
  if (j.is_discarded() || !j.contains("key") || !j["key"].is_object()) return std::nullopt;
  const json& k = j["key"];
  for (const char* part : {"settings", "receiver", "lights", "blockers"})
    if (!k.contains(part) || !k[part].is_string()) return std::nullopt;
  entry.key = {k["settings"], k["receiver"], k["lights"], k["blockers"]};
  return entry;
}

Expected<ReceiverBake> read_cached(const CachedReceiver& entry) {
  std::ifstream in(entry.metadata);
  const json j = json::parse(in, nullptr, false);
  if (j.is_discarded() || !j.contains("receiver"))
    return input_error(entry.metadata.string() + ": not a shadowbake cache entry");
  auto r = read_receiver(j["receiver"], entry.data, entry.metadata.string());
  if (!r) return r.error();
  r->key = entry.key;
  return r;
}

Expected<std::vector<ReuseDecision>> decide_reuse(const Scene& scene,
                                                  const std::vector<std::size_t>& receivers,
                                                  const std::vector<ReceiverKey>& keys,
                                                  const std::vector<std::vector<int>>& reaching,
                                                  const BakeOptions& options) {
  for (const std::string& name : options.only) {
    bool found = false;
    for (const ObjectDesc& o : scene.objects) found = found || (o.receiver && o.name == name);
    if (!found)
      return scene_error(scene.file.string() + ": --only " + name + ": no receiver has that name");
  }
  std::vector<int> relit;  // the scene lights --lights names
  for (const std::string& name : options.relight) {
    int found = -1;
    for (std::size_t l = 0; l < scene.lights.size(); ++l)
      if (scene.lights[l].name == name) found = int(l);
    if (found < 0)
      return scene_error(scene.file.string() + ": --lights " + name + ": no light has that name");
    relit.push_back(found);
  }
  const bool restricted = !options.only.empty() || !options.relight.empty();
  std::vector<ReuseDecision> out(receivers.size());
  for (std::size_t r = 0; r < receivers.size(); ++r) {
    const std::string& name = scene.objects[receivers[r]].name;
    std::string& why = out[r].why;
    std::string lit_by;
    for (int l : relit)
      if (std::find(reaching[r].begin(), reaching[r].end(), l) != reaching[r].end())
        lit_by = scene.lights[std::size_t(l)].name;
    if (options.force) {
      why = "--force";
    } else if (!lit_by.empty()) {
      why = "may be reached by --lights " + lit_by;
    } else if (std::find(options.only.begin(), options.only.end(), name) != options.only.end()) {
      why = "named by --only";
    } else if (options.reuse_from.empty()) {
      why = "no earlier bake to take it from";
    } else if (const auto entry = find_cached(options.reuse_from, name); !entry) {
      why = "no earlier bake of it";
    } else if (const std::string change = key_change(entry->key, keys[r]);
               !change.empty() && !restricted) {
      why = "changed: " + change;
    } else if (auto loaded = read_cached(*entry); !loaded) {
      why = "its earlier bake is unreadable (" + loaded.error().message + ")";
    } else {
      why = change.empty()
                ? "nothing that may reach it changed"
                : "left as it was: not named by --only or --lights (changed: " + change + ")";
      loaded->key = change.empty() ? keys[r] : entry->key;
      loaded->reuse = "reused";
      loaded->reuse_why = why;
      out[r].reused = std::move(*loaded);
    }
  }
  return out;
}

Expected<std::vector<std::string>> stage_cache(OutputFolder& folder, const BakeResult& result) {
  std::vector<std::string> names;
  for (const ReceiverBake& r : result.receivers) {
    if (r.reuse != "baked") continue;  // a reused one's entry stands as it was
    const std::string data = receiver_data(r);
    json metadata = receiver_metadata(r);
    metadata["checksum"] = data_checksum(data);
    const json entry = {{"key", key_json(r.key)}, {"receiver", metadata}};
    if (Status s = write_text_file(folder.staged(data_name(r.name)), data); !s) return s.error();
    if (Status s = write_text_file(folder.staged(metadata_name(r.name)), entry.dump(1) + "\n"); !s)
      return s.error();
    names.push_back(data_name(r.name));
    names.push_back(metadata_name(r.name));
  }
  return names;
}

void prune_cache(const fs::path& output_dir, const BakeResult& result) {
  std::set<std::string> keep;
  for (const ReceiverBake& r : result.receivers) {
    keep.insert(data_name(r.name));
    keep.insert(metadata_name(r.name));
  }
  std::error_code error;
  const fs::path dir = output_dir / kCacheFolder;
  std::vector<fs::path> stale;
  for (const auto& e : fs::directory_iterator(dir, error)) {
    const std::string name = (fs::path(kCacheFolder) / e.path().filename()).generic_string();
    if (e.is_regular_file(error) && !keep.count(name)) stale.push_back(e.path());
  }
  for (const fs::path& p : stale) fs::remove(p, error);
}

Expected<Reuse> reuse_from_cache(const Scene& scene, const MethodEntry& method,
                                 const LoadedScene& loaded, const BakeOptions& options) {
  const std::size_t n = loaded.receivers.size();
  Reuse reuse;
  reuse.keys.resize(n);
  reuse.reused.resize(n);
  reuse.why.resize(n);
  if (!options.keys) return reuse;
  // The keys' shaft tests: the method's culler, or one of their own for a local method.
  std::optional<ShaftCuller> own_culler;
  const ShaftCuller* culler = loaded.shafts ? &*loaded.shafts : nullptr;
  if (!culler && scene.bake.quantity != Quantity::ambient_occlusion && method.local) {
    own_culler.emplace(loaded.blockers);
    culler = &*own_culler;
  }
  KeyInputs in;
  in.scene = &scene;
  in.local = method.local;
  in.meshes = &loaded.meshes;
  in.lights = &loaded.lights;
  in.blockers = &loaded.blockers;
  in.culler = culler;
  in.keep_per_light = options.keep_per_light;
  in.keep_per_light.values |= scene.output.per_light;
  in.keep_per_light.visibility |= scene.output.shadowmask;
  std::vector<std::vector<int>> reaching;
  auto keys = receiver_keys(in, loaded.receivers, loaded.sides, &reaching);
  if (!keys) return keys.error();
  reuse.keys = std::move(*keys);
  auto decided = decide_reuse(scene, loaded.receivers, reuse.keys, reaching, options);
  if (!decided) return decided.error();
  for (std::size_t r = 0; r < n; ++r) {
    reuse.reused[r] = std::move((*decided)[r].reused);
    reuse.why[r] = std::move((*decided)[r].why);
  }
  return reuse;
}

}  // namespace sb
