// bin.glsl - the walk shared by bin_count and bin_fill (cuda/bin.cuh has the CUDA twin): each
// invocation takes one piece, sets its big triangle up (or loads its record), and visits the piece's
// tiles of the triangle's bbox (pieceTiles), keeping the tiles triangleTouchesTile accepts. The
// counting pass adds one to each kept tile's bin; the filling pass, run after the scan turned the counts
// into offsets (within the tile's scan block, plus the block's base in scanSums), takes a slot in each
// kept tile's bin and writes the ref there. Both passes make the same
// decisions, so every bin gets exactly the slots it counted. The including stage defines BIN_FILL.
// One invocation per piece; groups = ceil(pieceCapacity / GROUP_SIZE), idle past the piece count.
#ifndef RASTER_BIN_GLSL
#define RASTER_BIN_GLSL

void binPiece()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= min(counters[COUNTER_PIECES], params.pieceCapacity)) return;
    uvec2 piece = pieces[i];
    TriSetup t;
    if (!loadBinTriangle(piece.x, t)) return;
    ivec4 bounds = setupPixelBounds(t, params.width, params.height);
    ivec4 rect = tileRect(bounds);
    uint cols = uint(rect.z - rect.x + 1);
    uint tiles = tileCount(bounds);
    uint end = min(piece.y + pieceTiles(tiles), tiles);
    for (uint k = piece.y; k < end; ++k) {
        int tx = rect.x + int(k % cols);
        int ty = rect.y + int(k / cols);
        if (!triangleTouchesTile(t, bounds, tx, ty)) continue;
        uint tile = uint(ty) * params.tilesX + uint(tx);
#if BIN_FILL
        uint slot = scanSums[tile / uint(SCAN_GROUP_SIZE)] + atomicAdd(tileBins[tile], 1u);
        if (slot < params.binCapacity) binEntries[slot] = piece.x;
#else
        atomicAdd(tileBins[tile], 1u);
#endif
    }
}

#endif  // RASTER_BIN_GLSL
