// The [output] table of a scene file (docs/scene-format.md): which files a bake writes beside
// its manifest (encodings, per-light images, shadow masks, atlases, glTF), every value checked.
#include "scene/scene_file_tables.h"
#include "scene/toml_table_reader.h"

namespace sb {

const char* to_string(Encoding e) {
  switch (e) {
    case Encoding::linear_exr:
      return "linear-exr";
    case Encoding::half_exr:
      return "half-exr";
    case Encoding::png:
      return "png";
    case Encoding::rgbm_png:
      return "rgbm-png";
  }
  return "?";
}

std::optional<Encoding> parse_encoding(std::string_view text) {
  for (Encoding e : {Encoding::linear_exr, Encoding::half_exr, Encoding::png, Encoding::rgbm_png})
    if (text == to_string(e)) return e;
  return std::nullopt;
}

namespace {

// `atlas = { size = 2048, padding = 2 }` (or [output.atlas]), `atlas = true` for the defaults,
// `atlas = false` for none.
// Its problems are the atlas table's own (its keys' lines), returned as the error.
std::optional<Error> read_atlas(TableReader& r, const std::filesystem::path& file,
                                OutputSettings& out) {
  const toml::node* node = r.find("atlas");
  if (r.failed() || !node) return std::nullopt;
  if (const auto* on = node->as_boolean()) {
    if (on->get()) out.atlas = AtlasSettings{};
    return std::nullopt;
  }
  const toml::table* table = node->as_table();
  if (!table) {
    r.fail_got("atlas", "a table such as { size = 2048, padding = 2 }, or true");
    return std::nullopt;
  }
  TableReader atlas(file, *table, "[output] atlas");
  atlas.check_known_keys({"size", "padding"});
  AtlasSettings settings;
  if (auto v = atlas.integer("size", 64, 16384)) settings.size = static_cast<int>(*v);
  // At least a texel, so that a bilinear filter at a receiver's edge reads only its own texels.
  if (auto v = atlas.integer("padding", 1, 256)) settings.padding = static_cast<int>(*v);
  if (atlas.failed()) return atlas.error();
  out.atlas = settings;
  return std::nullopt;
}

}  // namespace

Expected<OutputSettings> read_output(const std::filesystem::path& file, const toml::table& table) {
  TableReader r(file, table, "[output]");
  r.check_known_keys(
      {"encoding", "per_light", "shadowmask", "shadowmask_encoding", "atlas", "gltf"});
  OutputSettings out;
  if (auto v = r.string("encoding")) {
    if (auto e = parse_encoding(*v)) {
      out.encoding = *e;
    } else {
      r.fail_got("encoding", "\"linear-exr\", \"half-exr\", \"png\" or \"rgbm-png\"");
    }
  }
  if (auto v = r.boolean("per_light")) out.per_light = *v;
  if (auto v = r.boolean("shadowmask")) out.shadowmask = *v;
  if (auto v = r.string("shadowmask_encoding")) {
    // A mask is a visibility in [0, 1]: RGBM's range buys nothing and costs its alpha channel.
    const auto e = parse_encoding(*v);
    if (e && *e != Encoding::rgbm_png) {
      out.shadowmask_encoding = *e;
    } else {
      r.fail_got("shadowmask_encoding", "\"png\", \"linear-exr\" or \"half-exr\"");
    }
  }
  const std::optional<Error> atlas_error = read_atlas(r, file, out);
  if (auto v = r.boolean("gltf")) out.gltf = *v;
  if (r.failed()) return r.error();
  if (atlas_error) return *atlas_error;
  return out;
}

}  // namespace sb
