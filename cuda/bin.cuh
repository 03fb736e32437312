// bin.cuh - the walk shared by bin_count and bin_fill (compute_glsl/bin.glsl has the GLSL twin): each
// thread takes one piece, sets its big triangle up (or loads its record), and visits the piece's
// tiles of the triangle's bbox (pieceTiles), keeping the tiles triangleTouchesTile accepts. The
// counting pass adds one to each kept tile's bin; the filling pass, run after the scan turned the counts
// into offsets (within the tile's scan block, plus the block's base in scanSums), takes a slot in each
// kept tile's bin and writes the ref there. Both passes make the same
// decisions, so every bin gets exactly the slots it counted.
// One thread per piece; blocks = ceil(pieceCapacity / GROUP_SIZE), idle past the piece count.
namespace sr {

template <bool kFill>
__device__ inline void binPiece(const RasterParams& params, const Buffers& b)
{
    uint i = globalThreadId();
    if (i >= min(b.counters[COUNTER_PIECES], params.pieceCapacity)) return;
    uvec2 piece = b.pieces[i];
    TriSetup t;
    if (!loadBinTriangle(params, b, piece.x, t)) return;
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
        if (kFill) {
            uint slot = b.scanSums[tile / uint(SCAN_GROUP_SIZE)] + atomicAdd(&b.tileBins[tile], 1u);
            if (slot < params.binCapacity) b.binEntries[slot] = piece.x;
        } else {
            atomicAdd(&b.tileBins[tile], 1u);
        }
    }
}

}  // namespace sr
