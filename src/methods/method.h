// The shape every bake method has. A method is an entry of the registry (registry.cpp): its name,
// what shared structures it needs built, the [bake] keys it reads, and a factory that checks its
// settings and returns a Method, which bakes one receiver at a time into a MethodResult. The
// pipeline (pipeline/bake.cpp) builds what the entries ask for, calls the method per receiver,
// and writes the result without knowing which method ran: method-specific figures travel as data
// (MethodReport).
#pragma once

#include <any>
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/error.h"
#include "core/image.h"
#include "core/memory_size.h"
#include "methods/light_mix.h"
#include "scene/lights.h"
#include "scene/mesh.h"
#include "scene/scene.h"
#include "texels/texel_space.h"

namespace sb {

class RayScene;
class ShaftCuller;
struct ClusterTree;

// Called from worker threads with the texels done so far; must be thread-safe and cheap.
using ProgressFn = std::function<void(double texels_done)>;

// Named figures a method reports per receiver (e.g. adaptive PCF's fraction of texels that took
// the full filter): the manifest's method_stats, printed by --explain.
using MethodStats = std::vector<std::pair<std::string, double>>;

// What a method needs the pipeline to build before its first receiver, shared by all of them.
struct MethodNeeds {
  bool rays = false;      // RayScene of the blockers (Embree)
  bool clusters = false;  // ClusterTree of the blockers (the convolution's planner)
  bool shafts = false;    // ShaftCuller of the blockers
};

// The bake's shared, read-only inputs, valid for the method's lifetime.
struct BakeContext {
  const Scene* scene = nullptr;  // settings, and the file name errors start with
  const std::vector<Light>* lights = nullptr;
  std::vector<const Mesh*> blockers;      // every blocker mesh, in scene order
  const RayScene* rays = nullptr;         // built when needs().rays
  const ClusterTree* clusters = nullptr;  // built when needs().clusters
  const ShaftCuller* shafts = nullptr;    // built when needs().shafts
  int threads = 1;                        // worker threads the bake runs on
  double memory_for_images = 0;  // bytes the budget leaves a method's images beyond the estimate
  KeepPerLight keep_per_light;   // per-light images wanted (MixedImages)
  // Progress within a receiver, for methods that report it as they go (the pipeline counts each
  // receiver's texels done when the method returns): a counter, and a callback with it.
  std::atomic<std::int64_t>* texels_done = nullptr;  // may be null
  ProgressFn progress;                               // may be empty
};

// One receiver to bake.
struct ReceiverInput {
  const TexelSpace* space = nullptr;
  const Mesh* mesh = nullptr;
  const ObjectDesc* object = nullptr;
  std::uint64_t stream = 0;  // the receiver's name's key (name_stream): its own random streams
  // Which lights may reach each block of its texels (light_lists.h): a method visits only those
  // pairs, so its cost follows the lights' reach. Null: the method makes its own.
  const LightLists* lists = nullptr;
};

// What a method says about one receiver beyond its values, as data the pipeline passes on.
struct MethodReport {
  MethodStats stats;
  // Further entries of the receiver's manifest object, written after method_stats (the
  // convolution's penumbra error and per-light frusta).
  nlohmann::ordered_json manifest = nlohmann::ordered_json::object();
  std::string explain;                // what --explain prints for the receiver after its stats
  std::vector<std::string> warnings;  // the bake's warnings, each a whole line
  // The method's own records, for its tests and benchmarks (the convolution's: a
  // std::vector<PairReport>, per light part and frustum); the pipeline passes them on unread.
  std::any details;
  // Counts over the kept texels that `stats` and `explain` derive from (MethodEntry::summarise),
  // for a method whose receivers can be baked in tiles: the join adds its tiles' and derives the
  // whole receiver's figures from the sums, as its bake in one piece would.
  std::vector<std::pair<std::string, std::int64_t>> tallies;
};

struct MethodResult {
  MixedImages images;  // combined (LightMix's rule) and, when asked, per light
  MethodReport report;
  std::int64_t rays = 0;  // shadow rays traced
};

class Method {
 public:
  virtual ~Method() = default;
  // Bakes one receiver. Called for receivers in scene order, one at a time (a method runs its
  // own work in parallel).
  virtual Expected<MethodResult> bake(const ReceiverInput& receiver) = 0;
};

// A tile of a receiver (pipeline/tiles.h) starts and ends on a multiple of this many rows.
inline constexpr int kTileRows = 32;

struct MethodEntry {
  std::string name;
  // The [bake] keys it shares with other methods beyond those of every bake (resolution, method,
  // quantity, margin, max_memory): samples, seed, ao_distance; with own_settings, what it reads
  // (others given in the scene are reported as ignored).
  std::vector<std::string> settings;
  // Its own [bake] keys: their defaults, types and checks (scene/scene.h's SettingSpec). The
  // scene reader, the manifest and the shard files take them from here, and the method reads
  // them with BakeSettings::flag/whole/number/word; a key may be declared by several methods
  // alike (the shadow-map baselines' `shadow_map`).
  std::vector<SettingSpec> own_settings;
  std::function<MethodNeeds(const BakeSettings&)> needs;
  // Its own large arrays for a bake of `scene` whose largest receiver has `texels` texels, beyond
  // texel space and the lightmaps (counted by pipeline/memory_budget.cpp), estimated before
  // anything is allocated; may be empty.
  std::function<std::vector<MemoryItem>(const Scene&, double texels)> memory;
  // Checks the settings (errors name the scene file and [bake]) and makes the method.
  std::function<Expected<std::unique_ptr<Method>>(const BakeContext&)> make;
  // Tiles (pipeline/tiles.h): the rows of texels beyond a tile's own that its bake must hold for
  // its own texels' values to be those of a bake of the whole receiver (a texel's value depends on
  // no texel further away); -1: its receivers cannot be split (a texel's value depends on the
  // whole receiver: a convolution's images, a shadow map fitted to the receiver).
  int tile_halo = -1;
  // Fills a report's stats and explain from its tallies; empty: the method reports no stats.
  std::function<void(MethodReport&)> summarise;
  // Whether a receiver's result depends on nothing of the scene but the lights that may reach
  // it and the blockers in their shafts (pipeline/bake_cache.h keys it by those alone); false
  // where the method fits something to the whole scene (shadow maps, clusters).
  bool local = false;
  // What `shadowbake plan` prints for one receiver, without baking; empty: the method has no
  // plan to show.
  std::function<Expected<std::string>(const BakeContext&, const ReceiverInput&)> plan;
  // The one quantity it bakes where it bakes no other (ambient occlusion's); the scene reader
  // pairs that quantity with it.
  std::optional<Quantity> only_quantity;
  // Its own settings the manifest records at its top level, as baked.
  std::vector<std::string> manifest_settings;
  // Whether it reads the [bake] key `key` (settings or own_settings).
  bool reads(std::string_view key) const;
};

// A method's own settings (MethodEntry::own_settings), by type: a switch; a whole number in
// [lo, hi] (`requirement` and `valid` for a further check); a number `valid` accepts
// (`requirement` says which); a word among `words` (the first of which need not be the default).
SettingSpec flag_setting(std::string key, bool fallback);
SettingSpec whole_setting(std::string key, std::int64_t fallback, std::int64_t lo, std::int64_t hi,
                          std::string requirement = {},
                          std::function<bool(std::int64_t)> valid = nullptr);
SettingSpec number_setting(std::string key, double fallback, std::string requirement,
                           std::function<bool(double)> valid);
SettingSpec word_setting(std::string key, std::string fallback, std::vector<std::string> words);

// Every method of this build, in the order docs/methods.md lists them.
const std::vector<MethodEntry>& method_registry();
// The entry named `name`, or null.
const MethodEntry* find_method(std::string_view name);

// Names of the methods this build knows, in the order docs/methods.md lists them.
const std::vector<std::string>& known_methods();
// The method that alone bakes `q` where one does (ambient occlusion's), else empty.
std::string method_baking_only(Quantity q);
// Every method's own settings, each key once, in the registry's order.
const std::vector<SettingSpec>& method_setting_specs();
// The one for `key`, or null.
const SettingSpec* find_method_setting(std::string_view key);
// What the scene reader is told of this build's methods (scene/scene.h).
const MethodVocabulary& method_vocabulary();
// The scene file read and checked against this build's methods (scene/scene.h's load_scene).
Expected<Scene> load_scene(const std::filesystem::path& file, bool need_lights = true);

// A method's own [bake] setting (SettingSpec) in `bake`: the value the scene file or the command
// line gave, else its registry default. A method reads its settings once per bake with these.
bool setting_flag(const BakeSettings& bake, std::string_view key);
std::int64_t setting_whole(const BakeSettings& bake, std::string_view key);
double setting_number(const BakeSettings& bake, std::string_view key);  // a whole number's too
std::string setting_word(const BakeSettings& bake, std::string_view key);
// Sets a method's own setting, a whole number made a number where the key takes one; not checked
// against its range (the scene reader checks what a file gives).
void set_setting(BakeSettings& bake, std::string_view key, SettingValue value);

}  // namespace sb
