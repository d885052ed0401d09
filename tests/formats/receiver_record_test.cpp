// Tests of a receiver's record on disk (src/formats/receiver_record.h, shard_files.h): the
// manifest and the shard files (and so the cache) write it alike, keep every field through a
// write and a read, and name a missing field.
#include "formats/receiver_record.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "formats/manifest.h"
#include "formats/shard_files.h"

namespace sb {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

ReceiverBake sample_receiver() {
  ReceiverBake r;
  r.object = 2;
  r.name = "floor";
  r.image = Image(4, 4, 3);
  r.covered.assign(16, 1);
  r.covered_texels = 16;
  r.most_lights_per_texel = 9;
  r.uv_layout.uv_area = 0.75;
  r.uv_layout.uv_area_outside = 0.125;
  r.uv_layout.overlapping_texels = 7;
  r.uv_layout.charts = 3;
  r.uv_layout.margin = 4;
  r.uv_layout.texels_near_other_charts = 11;
  r.uv_layout.stretch = 1.25;
  r.uv_layout.density_spread = 2.5;
  r.uv_layout.generated = true;
  r.seams.edges = 12;
  r.seams.texels = 300;
  r.seams.before = {.largest = 0.5, .visible = 0.25};
  r.seams.after = {.largest = 0.001, .visible = 0.0};
  r.seams.stitched = true;
  return r;
}

// The record's keys of a receiver's JSON, in their order.
json record_of(const json& receiver) {
  json out = json::object();
  for (const char* key : {"covered_texels", "most_lights_per_texel", "uv_layout", "seams"})
    out[key] = receiver.at(key);
  return out;
}

TEST(ReceiverRecord, ManifestAndShardFilesWriteItAlike) {
  const ReceiverBake r = sample_receiver();
  Manifest m;
  ManifestReceiver entry;
  entry.name = r.name;
  entry.files.emplace();
  static_cast<ReceiverRecord&>(entry) = r;
  m.receivers.push_back(entry);
  const json manifest = manifest_to_json(m);
  EXPECT_EQ(record_of(manifest["receivers"][0]).dump(), record_of(receiver_metadata(r)).dump());
  json written = json::object();
  write_record(r, written);
  EXPECT_EQ(written.dump(), record_of(receiver_metadata(r)).dump());
}

TEST(ReceiverRecord, AShardKeepsEveryField) {
  const ReceiverBake r = sample_receiver();
  const fs::path data = fs::temp_directory_path() /
                        ("shadowbake_receiver_record_" + std::to_string(::getpid()) + ".bin");
  const std::string bytes = receiver_data(r);
  std::ofstream(data, std::ios::binary) << bytes;
  json meta = receiver_metadata(r);
  meta["checksum"] = data_checksum(bytes);
  const auto read = read_receiver(meta, data, "shard.json");
  ASSERT_TRUE(read) << read.error().message;
  json before = json::object(), after = json::object();
  write_record(r, before);
  write_record(*read, after);
  EXPECT_EQ(after.dump(), before.dump());

  meta["uv_layout"].erase("charts");
  const auto damaged = read_receiver(meta, data, "shard.json");
  ASSERT_FALSE(damaged);
  EXPECT_EQ(damaged.error().message,
            "shard.json: no uv_layout.charts in the shard's data; bake the shard again");
  fs::remove(data);
}

}  // namespace
}  // namespace sb
