// A ceiling on ASA's output (the client's --max-display-faces): where the
// subdivided mesh would have more faces, the pixel tolerance is raised for
// this call until it fits (view-dependent), or levels are dropped
// (view-independent). A mesh already above the ceiling is left as it is.
#pragma once

#include <cstdint>

#include "common/asa/subdivide.h"

namespace meshstream {

struct BudgetOutcome {
  float pixel_tolerance = 0;  // the tolerance used (view-dependent; else 0)
  int levels = 0;             // the levels allowed in the run that was kept
  bool limited = false;       // the options asked for more than max_faces
  uint32_t runs = 0;          // subdivisions this call made
};

// A tolerance expected to bring `faces` (from `input_faces`) down to
// `max_faces`: faces on screen go as 1 / tolerance^2, so the tolerance grows
// by the square root of the excess of added faces, at least doubling (the
// first tolerance may lie where nothing changes yet).
float raised_tolerance(float tolerance, uint64_t input_faces, uint64_t faces, uint64_t max_faces);

// subdivide_into, then while result has more than max_faces faces (and
// max_faces > 0): again with a raised tolerance (at most 8 tries), or with
// one level fewer; finally the input unchanged. Errors as subdivide_into.
Status subdivide_within_budget(const Mesh& mesh, const AsaOptions& options, uint64_t max_faces,
                               AsaWorkspace& workspace, AsaResult& result, BudgetOutcome& outcome);

}  // namespace meshstream
