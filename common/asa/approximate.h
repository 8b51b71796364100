// An approximating post-processing for coarse prefixes (issue 20, point 4;
// the thesis's future work): Butterfly interpolates the decoded positions,
// so where they carry large errors it interpolates the errors. This step
// relaxes a mesh's vertices toward a smoother surface instead of passing
// through them: Taubin's lambda|mu filter (a shrink step then an inflate
// step, so a closed surface keeps its size), with each vertex moved only
// along its normal by the normal part of its umbrella Laplacian. So
//  - a flat region stays exactly where it is (its Laplacian has no normal
//    part) and vertices do not slide within the surface;
//  - boundary vertices, vertices on a sharp edge (faces meeting at more
//    than `sharp_degrees`) and vertices at non-manifold edges stay fixed,
//    so CAD edges and holes keep their shape.
// Pure: plain arrays in and out, no adjacency structure kept. The client
// runs it on the decoded prefix before ASA (`--approximate`, or the
// stream's guidance choosing it, asa_guidance.h), so that Butterfly
// interpolates relaxed positions instead of the errors (on a noisy sphere
// that is 4x the gain of relaxing ASA's output, asa_approximate_test); the
// encoder's guidance measures whether it pays.
#pragma once

#include "common/base/result.h"
#include "common/mesh/mesh.h"

namespace meshstream {

struct RelaxOptions {
  int iterations = 1;        // lambda|mu pairs
  float lambda = 0.5f;       // shrink step (0, 1)
  float mu = -0.53f;         // inflate step, |mu| > lambda (Taubin's pass band ~0.1)
  float sharp_degrees = 60;  // vertices on edges bending more than this stay fixed
};

// Relaxes `mesh.positions` in place; triangles and attributes are kept
// (per-vertex normals, if any, are left as they are: the renderer makes its
// own). kInvalidArgument for options out of range; errors of
// validate_arrays for a broken mesh. O(iterations * (V + F)) plus one sort
// of the 3F edges.
Status relax_toward_smooth(Mesh& mesh, const RelaxOptions& options = {});

}  // namespace meshstream
