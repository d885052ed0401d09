// The [[object]] tables of a scene file (docs/scene-format.md): name, mesh file, roles, UV
// channel and object transform.
#include "scene/mesh_reader.h"
#include "scene/scene_file_tables.h"
#include "scene/toml_table_reader.h"

namespace sb {

void set_uv(ObjectDesc& obj, int uv_set) {
  obj.auto_uv = uv_set == TableReader::kAutoUvSet;
  obj.uv_channel = obj.auto_uv ? 0 : uv_set;
}

bool is_file_name_char(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' ||
         c == '.' || c == '-';
}

bool is_file_name_part(std::string_view name) {
  if (name.empty() || name.front() == '.') return false;
  for (char c : name)
    if (!is_file_name_char(c)) return false;
  return true;
}

std::string object_location(const std::filesystem::path& scene_file, const ObjectDesc& obj) {
  return obj.line > 0 ? fmt::format("{}:{}: object '{}'", scene_file.string(), obj.line, obj.name)
                      : fmt::format("{}: object '{}'", scene_file.string(), obj.name);
}

Affine3 read_placement(TableReader& r) {
  const Vec3 translate = r.vec3("translate", "3 finite numbers", is_finite).value_or(Vec3::Zero());
  const Vec3 rotate_deg =
      r.vec3("rotate_deg", "3 finite numbers (degrees)", is_finite).value_or(Vec3::Zero());
  const Vec3 scale = r.vec3("scale", "3 finite non-zero numbers", [](double x) {
                        return std::isfinite(x) && x != 0;
                      }).value_or(Vec3::Ones());
  return object_transform(translate, rotate_deg, scale);
}

Expected<ObjectDesc> read_object(const std::filesystem::path& file, const toml::table& table,
                                 std::size_t index) {
  TableReader r(file, table, fmt::format("[[object]] #{}", index + 1));
  ObjectDesc obj;
  obj.line = static_cast<int>(r.line());
  if (r.require("name")) {
    if (auto name = r.string("name")) {
      if (is_file_name_part(*name)) {
        obj.name = *name;
        r.set_item(item_name("object", obj.name));
      } else {
        r.fail_got("name",
                   "usable as a file stem: letters, digits, '_', '.', '-', not starting with '.'");
      }
    }
  }
  r.check_known_keys({"name", "mesh", "receiver", "blocker", "uv", "allow_uncovered", "translate",
                      "rotate_deg", "scale", "lightmap_scale"});
  r.require("mesh");
  if (auto mesh = existing_file(r, file, "mesh", "mesh file")) obj.mesh = *mesh;
  if (auto v = r.boolean("receiver")) obj.receiver = *v;
  if (auto v = r.boolean("blocker")) obj.blocker = *v;
  if (auto v = r.boolean("allow_uncovered")) obj.allow_uncovered = *v;
  if (auto v = r.uv_set("uv", kMaxUvChannels - 1)) set_uv(obj, *v);
  obj.transform = read_placement(r);
  if (auto v = r.number("lightmap_scale", "a number > 0", is_positive)) obj.lightmap_scale = *v;
  if (r.failed()) return r.error();
  return obj;
}

}  // namespace sb
