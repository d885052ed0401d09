// The [bake] table of a scene file (docs/scene-format.md): resolution, method, sampling, memory
// and each method's settings, every value checked.
#include "scene/scene_file_tables.h"
#include "scene/toml_table_reader.h"

#include "core/memory_size.h"

namespace sb {

Expected<BakeSettings> read_bake(const std::filesystem::path& file, const toml::table& table) {
  TableReader r(file, table, "[bake]");
  r.check_known_keys({"resolution",
                      "texels_per_metre",
                      "method",
                      "quantity",
                      "samples",
                      "ao_distance",
                      "margin",
                      "seams",
                      "seed",
                      "max_memory",
                      "error_texels",
                      "max_image",
                      "max_triples",
                      "light_parts",
                      "trace",
                      "convolve",
                      "trace_error_texels",
                      "blocker_combine",
                      "weighting",
                      "shadow_map",
                      "pcf_radius",
                      "erosion_factor",
                      "light_rows",
                      "max_polygons",
                      "max_cell",
                      "interpolation_tolerance"});
  BakeSettings bake;
  const int int_max = std::numeric_limits<int>::max();
  if (auto v = r.integer("resolution", 1, 16384)) bake.resolution = static_cast<int>(*v);
  if (auto v = r.number("texels_per_metre", "a number > 0 (texels per metre of surface)",
                        [](double x) { return std::isfinite(x) && x > 0 && x <= 1e6; })) {
    if (r.find("resolution")) {
      r.fail("texels_per_metre",
             "give 'resolution' (texels per side of every lightmap) or 'texels_per_metre' (each "
             "lightmap sized by its surface area), not both");
    }
    bake.texels_per_metre = *v;
  }
  if (auto v = r.string("method")) {
    const auto& known = known_methods();
    if (std::find(known.begin(), known.end(), *v) == known.end()) {
      r.fail("method", fmt::format("unknown method {} (known: {})", single_quoted(*v),
                                   fmt::join(known, ", ")));
    }
    bake.method = *v;
  }
  if (auto v = r.string("quantity")) {
    if (*v == "visibility") {
      bake.quantity = Quantity::visibility;
    } else if (*v == "irradiance") {
      bake.quantity = Quantity::irradiance;
    } else if (*v == "ambient-occlusion") {
      bake.quantity = Quantity::ambient_occlusion;
    } else {
      r.fail_got("quantity", "\"visibility\", \"irradiance\" or \"ambient-occlusion\"");
    }
  }
  if (auto v = r.number("ao_distance", "a number > 0 (metres)",
                        [](double x) { return std::isfinite(x) && x > 0 && x <= 1e6; })) {
    bake.ao_distance = *v;
  }
  if (auto v = r.integer("samples", 1, int_max)) bake.samples = static_cast<int>(*v);
  if (auto v = r.integer("margin", 0, int_max)) bake.margin = static_cast<int>(*v);
  if (auto v = r.boolean("seams")) bake.seams = *v;
  if (auto v = r.integer("seed", 0, std::numeric_limits<std::int64_t>::max())) {
    bake.seed = static_cast<std::uint64_t>(*v);
  }
  if (const toml::node* node = r.find("max_memory"); node && !r.failed()) {
    // A size with its unit ("8 GiB", "512 MiB") or a whole number of bytes.
    const std::string_view requirement = "a size such as \"8 GiB\" or \"512 MiB\", or bytes";
    std::uint64_t bytes = 0;
    if (const auto* text = node->as_string(); text && parse_memory_size(text->get(), bytes)) {
      bake.max_memory = bytes;
    } else if (const auto* whole = node->as_integer(); whole && whole->get() > 0) {
      bake.max_memory = std::uint64_t(whole->get());
    } else {
      r.fail_got("max_memory", requirement);
    }
  }
  if (auto v = r.number("error_texels", "a number > 0", is_positive)) bake.error_texels = *v;
  if (auto v = r.boolean("trace")) bake.trace = *v;
  if (auto v = r.boolean("convolve")) bake.convolve = *v;
  if (auto v = r.number("trace_error_texels", "a number >= 0",
                        [](double x) { return std::isfinite(x) && x >= 0; })) {
    bake.trace_error_texels = *v;
  }
  if (auto v = r.integer("max_image", 64, 16384)) bake.max_image = static_cast<int>(*v);
  if (auto v = r.string("blocker_combine")) {
    if (*v == "product" || *v == "sum") {
      bake.blocker_combine = *v == "sum" ? BlockerCombine::sum : BlockerCombine::product;
    } else {
      r.fail_got("blocker_combine", "\"product\" or \"sum\"");
    }
  }
  if (auto v = r.string("weighting")) {
    if (*v == "irradiance" || *v == "emission") {
      bake.weighting =
          *v == "irradiance" ? ConvolutionWeighting::irradiance : ConvolutionWeighting::emission;
    } else {
      r.fail_got("weighting", "\"irradiance\" or \"emission\"");
    }
  }
  if (auto v = r.integer("max_triples", 1, 1 << 20)) bake.max_triples = static_cast<int>(*v);
  if (auto v = r.integer("light_parts", 1, 4)) {
    if (*v == 3) {
      r.fail_got("light_parts", "1, 2 or 4");
    } else {
      bake.light_parts = static_cast<int>(*v);
    }
  }
  if (auto v = r.integer("light_rows", 4, 64)) bake.light_rows = static_cast<int>(*v);
  if (auto v = r.integer("max_polygons", 0, 1 << 20)) bake.max_polygons = static_cast<int>(*v);
  if (auto v = r.integer("max_cell", 1, 8)) {
    if (*v != 1 && *v != 2 && *v != 4 && *v != 8) {
      r.fail_got("max_cell", "1, 2, 4 or 8");
    } else {
      bake.max_cell = static_cast<int>(*v);
    }
  }
  if (auto v = r.number("interpolation_tolerance", "a number >= 0 and < 1",
                        [](double x) { return std::isfinite(x) && x >= 0 && x < 1; })) {
    bake.interpolation_tolerance = *v;
  }
  if (auto v = r.integer("shadow_map", 64, 16384)) bake.shadow_map = static_cast<int>(*v);
  if (auto v = r.number("pcf_radius", "a number >= 0",
                        [](double x) { return std::isfinite(x) && x >= 0; })) {
    bake.pcf_radius = *v;
  }
  if (auto v = r.string("erosion_factor")) {
    if (*v == "pcf" || *v == "distance") {
      bake.erosion_factor = *v == "pcf" ? ErosionFactor::pcf : ErosionFactor::distance;
    } else {
      r.fail_got("erosion_factor", "\"pcf\" or \"distance\"");
    }
  }
  if (r.failed()) return r.error();
  // Where a mismatch of quantity and method is reported: the quantity's line, else the method's.
  if (const toml::node* given = r.find("quantity") ? r.find("quantity") : r.find("method")) {
    const std::string where =
        fmt::format("{}:{}: [bake]", file.string(), given->source().begin.line);
    if (Status paired = pair_quantity_and_method(bake, r.find("quantity") != nullptr,
                                                 r.find("method") != nullptr, where);
        !paired)
      return paired.error();
  }
  return bake;
}

}  // namespace sb
