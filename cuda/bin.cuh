// bin.cuh - the tile walk shared by setup, bin_count and bin_fill (compute_glsl/bin.glsl has the GLSL
// twin). A walk visits a run of a big triangle's bbox tiles and keeps those triangleTouchesTile accepts.
// Counting adds one to each kept tile's bin; filling, after the scan turned the counts into offsets
// (within the tile's scan block, plus the block's base in scanSums), takes a slot in each kept tile's bin
// and writes the ref there. Both make the same decisions, so every bin gets exactly the slots it counted.
// A triangle of one piece is counted by its setup thread, which has it at hand (its piece carries
// PIECE_COUNTED); bin_count sets up and counts the pieces of larger triangles.
namespace sr {

template <bool kFill, uint kMethod>
__device__ inline void binTiles(const RasterParams& params, const Buffers& b, const TriSetup& t, ivec4 bounds,
                                uint ref, uint first, uint end)
{
    ivec4 rect = tileRect(bounds);
    uint cols = uint(rect.z - rect.x + 1);
    for (uint k = first; k < end; ++k) {
        int tx = rect.x + int(k % cols);
        int ty = rect.y + int(k / cols);
        if (!methodTouchesTile<kMethod>(t, bounds, tx, ty, params.sampleBounds)) continue;
        uint tile = uint(ty) * params.tilesX + uint(tx);
        if (kFill) {
            uint slot = b.scanSums[tile / uint(SCAN_GROUP_SIZE)] + atomicAdd(&b.tileBins[tile], 1u);
            if (slot < params.binCapacity) b.binEntries[slot] = ref;
        } else {
            atomicAdd(&b.tileBins[tile], 1u);
        }
    }
}

// One thread per piece, striding over the pieces; blocks = RasterParams.binGroups.
template <bool kFill, uint kMethod>
__device__ inline void binPieces(const RasterParams& params, const Buffers& b)
{
    uint count = min(b.counters[COUNTER_PIECES], params.pieceCapacity);
    for (uint i = globalThreadId(); i < count; i += params.binGroups * uint(GROUP_SIZE)) {
        uvec2 piece = b.pieces[i];
        if (!kFill && (piece.y & PIECE_COUNTED) != 0u) continue;
        TriSetup t;
        if (!loadBinTriangle<kMethod>(params, b, piece.x, t)) continue;
        ivec4 bounds = methodPixelBounds<kMethod>(t, params.width, params.height, params.sampleBounds);
        uint tiles = tileCount(bounds);
        uint first = piece.y & ~PIECE_COUNTED;
        binTiles<kFill, kMethod>(params, b, t, bounds, piece.x, first, min(first + pieceTiles(tiles), tiles));
    }
}

}  // namespace sr
