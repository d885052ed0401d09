// Tiles: a receiver's texels split into bands of rows, so that one large receiver spreads over
// the shards of an array job (docs/distributed.md). A tile's bake rasterises its own rows and a
// halo of rows around them (MethodEntry::tile_halo: the rows its texels' values depend on), bakes
// them all, and keeps its own rows' values as the method left them; dilation, seams and the
// shadow-mask ranges need the whole lightmap, so the merge joins a receiver's tiles first and
// runs them on the whole. The result is the bytes of a bake of the receiver in one piece.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "core/error.h"
#include "pipeline/bake_types.h"
#include "scene/lights.h"
#include "scene/mesh.h"
#include "scene/scene.h"
#include "texels/texel_space.h"

namespace sb {

// A shard's piece of work: a receiver whole, or a tile of its rows.
struct ShardUnit {
  std::size_t receiver = 0;      // index among the scene's receivers (scene order)
  std::optional<RowRange> rows;  // a tile's rows (on multiples of kTileRows); none: whole
  bool operator==(const ShardUnit&) const = default;
};

// A receiver's estimated cost per block of kTileRows rows of its side × side lightmap: the
// (texel, light) pairs its method shades, what every method's time grows with. Per triangle, the
// texels its UVs cover (UV area × side²) times the lights that reach its centroid, plus a tenth of
// a light for the work every texel takes whatever the lights, spread over the blocks its UVs span.
std::vector<double> row_block_costs(const Mesh& mesh, int side, const std::vector<Light>& lights);

// The units of shard spec.index, in scene order (a receiver's tiles top to bottom). With `split`
// and more than one shard, a receiver that costs more than a shard's share (all costs / count) is
// cut into as many tiles of whole blocks as its cost holds shares (at most spec.count), of about
// equal cost; then units are dealt as spec.balance says (shard_receivers). The same costs give
// the same units.
std::vector<ShardUnit> shard_units(const std::vector<std::vector<double>>& block_costs,
                                   const std::vector<int>& sides, bool split,
                                   const ShardSpec& spec);

// The items a shard bakes (indices into `costs`, in order): `costs` per item (a receiver, or a
// tile) dealt to `spec.count` shards as spec.balance says. The same costs give the same shards.
std::vector<std::size_t> shard_receivers(const std::vector<double>& costs, const ShardSpec& spec);

// The rows a tile's bake rasterises: its own and `halo` on each side, within the lightmap.
RowRange tile_window(RowRange rows, int halo, int side);

// Keeps a tile's own rows of r's images and coverage (as its method left them: nothing dilated
// or stitched), and marks r a tile.
void crop_to_tile(ReceiverBake& r, const TexelSpace& space, RowRange rows);

// Joins each receiver's tiles (any order, each list one receiver's) into the receiver one bake
// makes: checks that they cover its rows once each, lays their rows into whole images, sums the
// method's tallies and rays, and runs what follows the method (receiver_stages.h) on the whole,
// with the meshes and lights as the bake read them. Errors (one line) name `where` and the
// receiver: missing or overlapping rows, tiles of other sizes, coverage the scene does not give.
Expected<std::vector<ReceiverBake>> join_tiles(const Scene& scene,
                                               std::vector<std::vector<ReceiverBake>> tiled,
                                               const std::string& where);

}  // namespace sb
