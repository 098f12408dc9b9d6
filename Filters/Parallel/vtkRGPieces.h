// How the volume sources (the plugin's readers and the CT phantom) cut a volume into a piece per
// rank: slabs of whole slices, each with the ghost slices the pipeline asks for, marked as VTK
// marks them; and the slices a piece asked for again shares with the one made before.
//
// The sources split the volume themselves (CAN_HANDLE_PIECE_REQUEST) rather than letting the
// executive do it (CAN_PRODUCE_SUB_EXTENT): VTK 9.2's executive cuts the extent in slabs on
// request but regenerates the ghost arrays for a BLOCK_MODE split, marking as ghosts cells that no
// rank owns; and it regenerates them value by value through vtkDataSet::GenerateGhostArray, about
// 2 s for each half of a 512^3 volume, where MarkGhosts fills rows in 0.1 s.
#ifndef vtkRGPieces_h
#define vtkRGPieces_h

#include <algorithm>

class vtkImageData;
class vtkInformation;

namespace rgmc
{

/// The piece of the volume of `whole` extent that `outInfo` asks for (UPDATE_PIECE_NUMBER of
/// UPDATE_NUMBER_OF_PIECES, with UPDATE_NUMBER_OF_GHOST_LEVELS, and one ghost level at least when
/// there is more than one piece, since RG Marching Cubes needs it): its extent with the ghost
/// slices and the part of it the piece owns, both in z slabs (vtkExtentTranslator's
/// Z_SLAB_MODE), and within UPDATE_EXTENT where a consumer asks for less than the whole volume
/// (a VOI). With more pieces than layers of cells, a layer a piece and the rest empty. False
/// when the piece is empty (past the last layer, or with nothing of it in the VOI).
///
/// Pieces made with their ghost slice from the start: ParaView updates a source without ghost
/// levels first (when it is applied, or by a script's UpdatePipeline), and a piece made without
/// them was made again, copied slice by slice, once the extraction asked for them (1 s a rank on
/// the 512^3 phantom on 2 ranks).
bool SlabPiece(vtkInformation* outInfo, const int whole[6], int extent[6], int owned[6]);

/// Marks the points and cells of `image` outside `owned` as ghosts in vtkGhostType arrays: the
/// values vtkDataSet::GenerateGhostArray(owned) gives (DUPLICATEPOINT on points outside `owned`,
/// DUPLICATECELL on cells outside it, an axis of one point taken as one cell), filled a row at a
/// time on threads, with their ranges stored (CacheRanges), and the ghost levels made in the
/// image's DATA_NUMBER_OF_GHOST_LEVELS. An image that has a ghost array already is left to VTK,
/// which adds to it. Nothing when `owned` is the image's whole extent.
void MarkGhosts(vtkImageData* image, const int owned[6]);

/// The slices [lo, hi] that a piece of `extent` shares with one of `previous` (the piece a
/// source made before, asked for again with ghost slices): both must have the same rows and
/// columns; false when they share none.
inline bool SharedSlices(const int extent[6], const int previous[6], int& lo, int& hi)
{
  lo = std::max(extent[4], previous[4]);
  hi = std::min(extent[5], previous[5]);
  return std::equal(extent, extent + 4, previous) && lo <= hi;
}

} // namespace rgmc

#endif
