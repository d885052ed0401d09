// A receiver's record: what every file that keeps a receiver says of its bake beyond its images
// and timings — the texels it covers, its lightmap UV layout's checks, its UV seams. A bake's
// ReceiverBake (bake_types.h) and the manifest's ManifestReceiver (manifest.h) are each a record
// and more; write_record and read_record are the one writer and reader of it for the manifest,
// the shard files (shard_files.h) and the cache (bake_cache.h, which keeps a receiver as a shard
// does), so that the three never spell a field differently.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>

#include "formats/json_fields.h"
#include "texels/seams.h"
#include "texels/uv_checks.h"

namespace sb {

struct ReceiverRecord {
  std::int64_t covered_texels = 0;  // texels a triangle covers (its lightmap's, a tile's rows')
  // The most lights that reach one of its texels (H0 > 0 there): how many the bake summed at most
  // for one texel, what a level of many lights costs per texel.
  std::int64_t most_lights_per_texel = 0;
  UvLayoutReport uv_layout;  // the lightmap UV layout's checks
  // Its UV seams: how many, the texels stitched, and the largest difference of the two sides'
  // lookups before and after (texels/seams.h; after = before when [bake] seams is false).
  SeamReport seams;
};

// Adds the record's keys to `into`, in the manifest schema's order: "covered_texels",
// "most_lights_per_texel", "uv_layout" {"charts", "uv_area", "uv_area_outside",
// "overlapping_texels", "texels_near_other_charts", "margin", "stretch", "density_spread",
// "generated"}, "seams"
// {"edges", "stitched", "texels", "largest_difference_before", "largest_difference_after",
// "visible_before", "visible_after"}.
void write_record(const ReceiverRecord& record, nlohmann::ordered_json& into);

// Reads what write_record wrote from the object `fields` reads, keeping the first problem in
// its status. Absent from manifests written before they were measured, and taken as 0 there:
// "most_lights_per_texel", "seams", and the layout's "stretch", "density_spread" and
// "generated".
void read_record(FieldReader& fields, const nlohmann::ordered_json& object, ReceiverRecord& record);

}  // namespace sb
