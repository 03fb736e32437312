// bin.glsl - the tile walk shared by setup, bin_count and bin_fill (cuda/bin.cuh has the CUDA twin). A
// walk visits a run of a big triangle's bbox tiles and keeps those triangleTouchesTile accepts.
// Counting adds one to each kept tile's bin; filling, after the scan turned the counts into offsets
// (within the tile's scan block, plus the block's base in scanSums), takes a slot in each kept tile's bin
// and writes the ref there. Both make the same decisions, so every bin gets exactly the slots it counted.
// A triangle of one piece is counted by its setup thread, which has it at hand (its piece carries
// PIECE_COUNTED); bin_count sets up and counts the pieces of larger triangles.
#ifndef RASTER_BIN_GLSL
#define RASTER_BIN_GLSL

void binTiles(TriSetup t, ivec4 bounds, uint ref, uint first, uint end, bool fill)
{
    ivec4 rect = tileRect(bounds);
    uint cols = uint(rect.z - rect.x + 1);
    for (uint k = first; k < end; ++k) {
        int tx = rect.x + int(k % cols);
        int ty = rect.y + int(k / cols);
        if (!methodTouchesTile(t, bounds, tx, ty, params.sampleBounds)) continue;
        uint tile = uint(ty) * params.tilesX + uint(tx);
        if (fill) {
            uint slot = scanSums[tile / uint(SCAN_GROUP_SIZE)] + atomicAdd(tileBins[tile], 1u);
            if (slot < params.binCapacity) binEntries[slot] = ref;
        } else {
            atomicAdd(tileBins[tile], 1u);
        }
    }
}

// One invocation per piece, striding over the pieces; groups = RasterParams.binGroups.
void binPieces(bool fill)
{
    uint count = min(counters[COUNTER_PIECES], params.pieceCapacity);
    for (uint i = gl_GlobalInvocationID.x; i < count; i += params.binGroups * uint(GROUP_SIZE)) {
        uvec2 piece = pieces[i];
        if (!fill && (piece.y & PIECE_COUNTED) != 0u) continue;
        TriSetup t;
        if (!loadBinTriangle(piece.x, t)) continue;
        ivec4 bounds = methodPixelBounds(t, params.width, params.height, params.sampleBounds);
        uint tiles = tileCount(bounds);
        uint first = piece.y & ~PIECE_COUNTED;
        binTiles(t, bounds, piece.x, first, min(first + pieceTiles(tiles), tiles), fill);
    }
}

#endif  // RASTER_BIN_GLSL
