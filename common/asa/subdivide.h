// ASA: adaptive modified-Butterfly subdivision driven by local flatness
// (Cheang 1998; stencils of Zorin, Schröder and Sweldens 1996). See
// docs/algorithms.md sections 2 and 3.
//
// The module, one job per file:
//   butterfly_stencils  every Butterfly rule (regular ten-point with tension,
//                       K = 3, 4, >= 5, both-extraordinary average, boundary
//                       four-point, boundary-touching interior edges exactly as
//                       OpenMesh's ModifiedButterFlyT, creases, projection);
//                       the rules themselves are inline in butterfly_rules.h
//   edge_points         every new edge point of a level in two passes
//                       (regular stencils, then each extraordinary centre's
//                       stencils from one gathered ring), bit-identical to
//                       the per-edge rules
//   flatness            face normals, crease tagging, flatness targets
//   closure             conforming closure with red-green rules (worklist)
//   split_uniform       1-to-4 split of every face, child corner table by
//                       index arithmetic
//   split_adaptive      keep / bisect / 1-to-4 / re-split a green pair's parent;
//                       writes the next level's normals and which faces
//                       changed, so flatness is re-tested only there
//   corner_table        fast opposite-corner builder for the input
//   subdivide           levels, attributes, buffers (this header)
//   incremental         redo only the region a change touched (incremental.h)
//
// Output order: the input's vertices first (same index, bit-identical
// position), then one new vertex per split edge, level by level. Faces:
// each input face's descendants are contiguous, in input face order.
// Attributes: colours and texture coordinates of a new vertex are the
// average of its edge's endpoints (linear: colours stay in range, texture
// coordinates stay on their chart); normals, when the input has them, are
// recomputed (area-weighted) on the output.
// Creases (crease_degrees > 0): edges bending more than the angle at level 0
// are tagged; their halves stay tagged at every level. They get the curve
// four-point rule; a vertex with other than two crease/boundary edges is a
// corner (the curve is extended past it by reflection); no interior stencil
// reaches across a crease (wings across it are reflected, crease vertices are
// never extraordinary centres). In ASA mode crease edges do not mark their
// faces as targets: they are sharp on purpose.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "common/asa/view.h"
#include "common/base/result.h"
#include "common/mesh/mesh.h"

namespace meshstream {

enum class ButterflyRule {
  kZorin,       // weights applied to 3-D points
  kProjection,  // the thesis's local planar parameterization
};

struct AsaOptions {
  int levels = 1;          // with a camera (view.enabled): the most levels the screen may ask for
  float flatness = 0.85f;  // t: an interior edge is flat when t < N1.N2 <= 1
  bool uniform = false;    // split every triangle (classic modified Butterfly)
  ButterflyRule rule = ButterflyRule::kZorin;
  float tension = 0.0f;      // omega of the ten-point stencil
  float crease_degrees = 0;  // > 0: edges bending more than this stay sharp
  // No spikes (issue 20): a new vertex's offset from its edge's midpoint is
  // capped by the edge's length and the stencil's dihedral angles, and an
  // irregular stencil gets a gentler cap (butterfly_rules.h, bound_offset).
  // Off: the plain rules (for comparisons; no program exposes it).
  bool bound_offsets = true;
  bool track_source_faces = false;  // fill AsaResult::source_face
  // View-dependent ASA (view.h): a bent edge is refined only where it
  // matters on screen for this camera. Off: the whole mesh, as the thesis.
  AsaView view;
};

// Per-face label of the last level, for viewers: what ASA did to it.
enum class FaceKind : uint8_t { kUntouched = 0, kTarget = 1, kBisected = 2 };

struct AsaResult {
  Mesh mesh;
  std::vector<FaceKind> face_kind;  // one per output face
  // With AsaOptions::track_source_faces: per output face, the input face it
  // descends from. Each input face's descendants are contiguous and in input
  // face order (the incremental update relies on it).
  std::vector<uint32_t> source_face;
};

// What the last call did, per level (for tests, benchmarks and viewers).
struct AsaStats {
  std::vector<uint32_t> targets;      // faces marked by flatness (uniform: all)
  std::vector<uint32_t> split_edges;  // new vertices added
};

// Buffers reused across calls (the client calls ASA after every record).
class AsaWorkspace {
 public:
  AsaWorkspace();
  ~AsaWorkspace();
  AsaWorkspace(AsaWorkspace&&) noexcept;
  AsaWorkspace& operator=(AsaWorkspace&&) noexcept;
  struct Buffers;
  Buffers& buffers();
  const AsaStats& last_stats() const;

 private:
  std::unique_ptr<Buffers> buffers_;
};

// Subdivides a manifold mesh. Old vertices keep their index and position
// bit for bit; new vertices follow. kNonManifold for a mesh adjacency cannot
// be built on; kInvalidArgument for bad options.
Result<AsaResult> subdivide(const Mesh& mesh, const AsaOptions& options);
Result<AsaResult> subdivide(const Mesh& mesh, const AsaOptions& options, AsaWorkspace& workspace);

// Same, writing into `result` so that its arrays' capacity is reused too
// (with the workspace, a repeated call allocates nothing once warmed up).
// Cost: O(output size) per level; adjacency of the input is built once
// (O(V + F)), later levels derive theirs while splitting. On error `result`
// is left unspecified. Bad input: errors from validate_arrays and
// Adjacency::build; kInvalidArgument for options out of range; kLimit when
// the output would exceed 1e9 faces. `result.mesh` must not be `mesh` itself.
Status subdivide_into(const Mesh& mesh, const AsaOptions& options, AsaWorkspace& workspace,
                      AsaResult& result);

}  // namespace meshstream
