// A receiver's record as JSON (receiver_record.h).
#include "formats/receiver_record.h"

namespace sb {

using json = nlohmann::ordered_json;

void write_record(const ReceiverRecord& record, json& into) {
  const UvLayoutReport& layout = record.uv_layout;
  const SeamReport& seams = record.seams;
  into["covered_texels"] = record.covered_texels;
  into["most_lights_per_texel"] = record.most_lights_per_texel;
  into["uv_layout"] = {{"charts", layout.charts},
                       {"uv_area", layout.uv_area},
                       {"uv_area_outside", layout.uv_area_outside},
                       {"overlapping_texels", layout.overlapping_texels},
                       {"texels_near_other_charts", layout.texels_near_other_charts},
                       {"margin", layout.margin},
                       {"stretch", layout.stretch},
                       {"density_spread", layout.density_spread},
                       {"generated", layout.generated}};
  into["seams"] = {{"edges", seams.edges},
                   {"stitched", seams.stitched},
                   {"texels", seams.texels},
                   {"largest_difference_before", seams.before.largest},
                   {"largest_difference_after", seams.after.largest},
                   {"visible_before", seams.before.visible},
                   {"visible_after", seams.after.visible}};
}

void read_record(FieldReader& fields, const json& object, ReceiverRecord& record) {
  fields.read("covered_texels", record.covered_texels);
  if (object.contains("most_lights_per_texel"))
    fields.read("most_lights_per_texel", record.most_lights_per_texel);
  if (const json* layout = fields.object("uv_layout")) {
    FieldReader in = fields.nested(*layout, "uv_layout");
    UvLayoutReport& out = record.uv_layout;
    in.read("charts", out.charts);
    in.read("uv_area", out.uv_area);
    in.read("uv_area_outside", out.uv_area_outside);
    in.read("overlapping_texels", out.overlapping_texels);
    in.read("texels_near_other_charts", out.texels_near_other_charts);
    in.read("margin", out.margin);
    if (layout->contains("stretch")) in.read("stretch", out.stretch);
    if (layout->contains("density_spread")) in.read("density_spread", out.density_spread);
    if (layout->contains("generated")) in.read("generated", out.generated);
  }
  if (const json* seams = object.contains("seams") ? fields.object("seams") : nullptr) {
    FieldReader in = fields.nested(*seams, "seams");
    SeamReport& out = record.seams;
    in.read("edges", out.edges);
    in.read("stitched", out.stitched);
    in.read("texels", out.texels);
    in.read("largest_difference_before", out.before.largest);
    in.read("largest_difference_after", out.after.largest);
    in.read("visible_before", out.before.visible);
    in.read("visible_after", out.after.visible);
  }
}

}  // namespace sb
