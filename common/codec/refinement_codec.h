// Refinement records, the overview; each job has its own header, all
// included here: the state both sides keep (refinement_state.h), the
// symbol models (structure_models.h) and their contexts
// (structure_contexts.h), patch geometry and insertion (patch_geometry.h),
// position prediction and coarse residuals (insertion_prediction.h), record
// headers (record_header.h), plane records (plane_record.h) and the reader
// of a record (structure_record_reader.h). Encoder and decoder share every
// step but the symbols' order, so the two sides cannot drift.
//
// How a layer is described (HCS's "structure data", our own layout):
// the decoder walks the coarse vertices in the *order list* (base vertices in
// base order; every inserted vertex is linked right after the apex of its
// patch, so list neighbours are surface neighbours and a slice of the list is
// a spatially coherent batch). At each vertex u present before the layer it
// reads how many patches have their fan apex at u, and for each: k, the
// valence of the vertex to insert (the fan has k-2 faces), and which run of
// k-2 faces of u's star is the fan, as a rank among the runs that fit,
// ordered by how much they look like a fan (longest diagonals first: a fan
// over a removed vertex's hole has long edges from the apex; this saves a
// third of the bits of a plain star index); when ring edges
// of the patch lie on the boundary, which of them (if any) the vertex
// re-enters as a boundary vertex. Then the vertex's
// position as a residual from the prediction (average of the k ring vertices,
// HCS's neighbour average), per axis, through models chosen by the ring's
// size on the grid (bigger rings, bigger residuals).
//
// A record covers a run of the walk (a batch); the first record of a layer
// restarts the walk. Record payload: u8 flags (bit 0: starts a layer),
// varint walk steps, varint insertions, in the embedded formats varint min
// shift (record_header.h), then one range-coded block.
// Format 3 (kRefinementFormat) keeps this layout and codes the same symbols
// through models that learn faster at first (FastStartBitModel), with the valence
// also by the apex's free faces and the start rank by the number of
// candidate runs and the lead of the best (docs/hcs-format.md).
#pragma once

#include "common/codec/insertion_prediction.h"
#include "common/codec/patch_geometry.h"
#include "common/codec/plane_record.h"
#include "common/codec/record_header.h"
#include "common/codec/refinement_state.h"
#include "common/codec/stream_format.h"
#include "common/codec/structure_contexts.h"
#include "common/codec/structure_models.h"
#include "common/codec/structure_record_reader.h"

namespace meshstream {}  // namespace meshstream
