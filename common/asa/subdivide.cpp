// ASA driver: levels of flatness marking, closure and splitting (Cheang 1998,
// docs/algorithms.md section 3), or uniform modified Butterfly levels.
#include "common/asa/subdivide.h"

#include <cmath>
#include <cstring>
#include <optional>
#include <string>
#include <utility>

#include "common/asa/butterfly_stencils.h"
#include "common/asa/closure.h"
#include "common/asa/corner_attributes.h"
#include "common/asa/corner_table.h"
#include "common/asa/flatness.h"
#include "common/asa/level_mesh.h"
#include "common/asa/split.h"

namespace meshstream {

struct AsaWorkspace::Buffers {
  asa::LevelMesh base;       // level 0 topology (positions stay in the input)
  asa::LevelMesh levels[2];  // ping-pong between levels
  asa::ButterflyWeights weights;
  asa::ClosureBuffers closure;
  asa::SplitScratch scratch;
  asa::CornerTableScratch corner_scratch;
  std::vector<Vec3f> normals;
  std::vector<uint8_t> target;
  std::vector<uint8_t> fresh;      // per face of the current level: made by the last split
  std::vector<uint32_t> identity;  // level-0 source faces
  std::vector<uint32_t> parents;   // per vertex id: its two parents (corner_attributes.h)
  AsaStats stats;
};

AsaWorkspace::AsaWorkspace() : buffers_(std::make_unique<Buffers>()) {}
AsaWorkspace::~AsaWorkspace() = default;
AsaWorkspace::AsaWorkspace(AsaWorkspace&&) noexcept = default;
AsaWorkspace& AsaWorkspace::operator=(AsaWorkspace&&) noexcept = default;
AsaWorkspace::Buffers& AsaWorkspace::buffers() { return *buffers_; }
const AsaStats& AsaWorkspace::last_stats() const { return buffers_->stats; }

namespace {

Status check_options(const AsaOptions& o) {
  if (o.levels < 0 || o.levels > 8) {
    return make_error(ErrorCode::kInvalidArgument,
                      "levels must be between 0 and 8 (got " + std::to_string(o.levels) + ")");
  }
  if (!std::isfinite(o.flatness) || o.flatness < -1.0f || o.flatness > 1.0f) {
    return make_error(ErrorCode::kInvalidArgument, "flatness t must be in [-1, 1]");
  }
  if (!std::isfinite(o.tension) || std::fabs(o.tension) > 0.25f) {
    return make_error(ErrorCode::kInvalidArgument, "tension must be in [-0.25, 0.25]");
  }
  if (!std::isfinite(o.crease_degrees) || o.crease_degrees < 0 || o.crease_degrees > 180) {
    return make_error(ErrorCode::kInvalidArgument, "crease angle must be in [0, 180] degrees");
  }
  return check_view(o.view);
}

// Levels multiply faces by up to 4 each; refuse what cannot be indexed.
Status check_output_size(const Mesh& mesh, const AsaOptions& options) {
  const double projected = static_cast<double>(mesh.face_count()) * std::pow(4.0, options.levels);
  if (projected > 1.0e9) {
    return make_error(ErrorCode::kLimit, "subdividing " + std::to_string(mesh.face_count()) +
                                             " faces " + std::to_string(options.levels) +
                                             " times exceeds 1e9 faces");
  }
  return {};
}

// Level 0: the caller's arrays plus our corner table, feature flags and
// faces per vertex, and the Butterfly weights for its valences.
Status build_base_level(const Mesh& mesh, const AsaOptions& options, AsaWorkspace::Buffers& ws,
                        asa::LevelView& view) {
  const uint32_t F = mesh.face_count(), V = mesh.vertex_count();
  asa::LevelMesh& base = ws.base;
  if (auto built = asa::build_opposites(mesh, base.opposite, base.across, ws.corner_scratch);
      !built)
    return built;
  view = {};
  view.positions = mesh.positions.data();
  view.corner_vertex = F ? mesh.triangles.front().data() : nullptr;
  view.opposite = base.opposite.data();
  view.across = base.across.data();
  view.vertex_count = V;
  view.face_count = F;
  // Normals: for crease tagging and flatness (the uniform scheme needs none).
  const bool need_normals = options.crease_degrees > 0 || !options.uniform;
  if (need_normals) asa::compute_face_normals(view, ws.normals);
  const uint32_t tagged =
      asa::tag_feature_edges(view, options.crease_degrees, ws.normals, base.feature_edge);
  view.feature_edge = base.feature_edge.data();
  if (tagged) {
    asa::count_vertex_features(view, base.vertex_features);
  } else {
    base.vertex_features.assign(V, 0);  // closed and no creases
  }
  view.vertex_features = base.vertex_features.data();
  asa::faces_per_vertex(ws.corner_scratch, base.valence);
  view.valence = base.valence.data();
  view.green = nullptr;
  ws.weights.configure(options.tension, options.bound_offsets);
  ws.weights.add_valences(base.valence.data(), base.vertex_features.data(), V);
  return {};
}

// The result is the level `in` as it stands (nothing bends any more): its
// arrays copied, every face untouched, normals recomputed when wanted.
void copy_level_unchanged(const asa::SplitInput& in, bool normals, AsaResult& result) {
  const asa::LevelView& view = in.mesh;
  const size_t V = view.vertex_count, F = view.face_count;
  result.mesh.positions.assign(view.positions, view.positions + V);
  result.mesh.triangles.resize(F);
  if (F) std::memcpy(result.mesh.triangles.data(), view.corner_vertex, F * sizeof(Triangle));
  if (in.colors)
    result.mesh.colors.assign(in.colors, in.colors + V);
  else
    result.mesh.colors.clear();
  if (in.texcoords)
    result.mesh.texcoords.assign(in.texcoords, in.texcoords + V);
  else
    result.mesh.texcoords.clear();
  result.face_kind.assign(F, FaceKind::kUntouched);
  if (in.source)
    result.source_face.assign(in.source, in.source + F);
  else
    result.source_face.clear();
  if (normals)
    result.mesh.normals = compute_vertex_normals(result.mesh);
  else
    result.mesh.normals.clear();
}

// One adaptive level of `in` into `out`: flatness targets, closure, split.
// Level 0 tests every edge; later levels only the edges of faces the last
// split made (their normals came with the split), unless most faces are new
// anyway. Returns false, leaving `out` alone, when no face is a target.
bool split_adaptive_level(int level, const AsaOptions& options, const asa::ViewTest* camera,
                          asa::SplitInput& in, AsaWorkspace::Buffers& ws, asa::LevelMesh& out,
                          std::vector<FaceKind>* kinds) {
  const asa::LevelView& view = in.mesh;
  const bool mostly_fresh =
      level > 0 && 2 * static_cast<uint64_t>(ws.scratch.fresh_count) > view.face_count;
  const uint32_t targets =
      level == 0 || mostly_fresh
          ? asa::mark_targets(view, ws.normals, options.flatness, ws.target, camera)
          : asa::mark_targets_near_fresh(view, ws.normals, ws.fresh, options.flatness, ws.target,
                                         camera);
  if (targets == 0) return false;
  const uint32_t split = asa::close_targets(view, ws.target.data(), ws.closure);
  in.normals = ws.normals.data();
  asa::split_adaptive(in, ws.closure, ws.scratch, out, kinds);
  if (in.want_topology) {
    std::swap(ws.normals, out.normals);
    std::swap(ws.fresh, out.fresh);
  }
  ws.stats.targets.push_back(targets);
  ws.stats.split_edges.push_back(split);
  return true;
}

// `out` becomes the next level's input. Adaptive bisections change valences
// (the split counted them): any new ones get weights, looking only at new
// vertices and those of replaced faces.
void advance_to(asa::LevelMesh& out, bool uniform, AsaWorkspace::Buffers& ws, asa::SplitInput& in) {
  if (!uniform) {
    ws.weights.add_valences(out.valence.data(), out.vertex_features.data(), ws.scratch.touched);
    ws.weights.add_valences(out.valence.data(), out.vertex_features.data(), in.mesh.vertex_count,
                            static_cast<uint32_t>(out.valence.size()) - in.mesh.vertex_count);
  }
  in.mesh = out.view();
  if (in.source) in.source = out.source.data();
  in.colors = out.colors.empty() ? nullptr : out.colors.data();
  in.texcoords = out.texcoords.empty() ? nullptr : out.texcoords.data();
}

// The last level's arrays move into the result.
void take_last_level(asa::LevelMesh& out, bool source, bool normals, AsaResult& result) {
  std::swap(result.mesh.positions, out.positions);
  std::swap(result.mesh.triangles, out.triangles);
  std::swap(result.mesh.colors, out.colors);
  std::swap(result.mesh.texcoords, out.texcoords);
  if (source)
    std::swap(result.source_face, out.source);
  else
    result.source_face.clear();
  if (normals) {
    result.mesh.normals = compute_vertex_normals(result.mesh);
  } else {
    result.mesh.normals.clear();
  }
}

// With a camera: can any edge of the mesh matter on screen? Each face asks
// for its three edges with its own normal on both sides: an interior edge
// is asked from both its faces, so it passes here exactly when the real
// test (both normals) would let it through from either side. One pass over
// the faces, no adjacency: when nothing may matter, ASA is a copy.
bool any_edge_may_matter(const Mesh& mesh, const asa::ViewTest& view) {
  const Vec3f* p = mesh.positions.data();
  for (const Triangle& t : mesh.triangles) {
    const Vec3f a = p[t[0]], b = p[t[1]], c = p[t[2]];
    const Vec3f n = normalized(cross(b - a, c - a));
    if (view.matters(a, b, n, n) || view.matters(b, c, n, n) || view.matters(c, a, n, n))
      return true;
  }
  return false;
}

}  // namespace

Status subdivide_into(const Mesh& mesh, const AsaOptions& options, AsaWorkspace& workspace,
                      AsaResult& result) {
  if (auto ok = check_options(options); !ok) return ok;
  if (auto ok = validate_arrays(mesh); !ok) return ok;
  if (auto ok = check_output_size(mesh, options); !ok) return ok;

  AsaWorkspace::Buffers& ws = workspace.buffers();
  ws.scratch.points.fans_valid = false;  // a new input: fans are walked again
  ws.stats.targets.clear();
  ws.stats.split_edges.clear();
  const uint32_t F = mesh.face_count();

  std::optional<asa::ViewTest> camera;
  if (options.view.enabled && !options.uniform) camera.emplace(options.view);
  if (camera && options.levels > 0 && F > 0 && !any_edge_may_matter(mesh, *camera)) {
    // The mesh is finer than the tolerance (or out of view) everywhere:
    // what the levels would give, without building adjacency.
    result.mesh.positions = mesh.positions;
    result.mesh.triangles = mesh.triangles;
    result.mesh.colors = mesh.colors;
    result.mesh.texcoords = mesh.texcoords;
    result.mesh.corner_normals = mesh.corner_normals;
    result.mesh.corner_colors = mesh.corner_colors;
    result.mesh.corner_texcoords = mesh.corner_texcoords;
    result.mesh.face_materials = mesh.face_materials;
    result.mesh.materials = mesh.materials;
    result.mesh.textures = mesh.textures;
    result.mesh.normals.clear();
    if (!mesh.normals.empty()) result.mesh.normals = compute_vertex_normals(result.mesh);
    result.face_kind.assign(F, FaceKind::kUntouched);
    result.source_face.resize(options.track_source_faces ? F : 0);
    for (uint32_t f = 0; f < result.source_face.size(); ++f) result.source_face[f] = f;
    ws.stats.targets.assign(options.levels, 0);
    ws.stats.split_edges.assign(options.levels, 0);
    return {};
  }

  asa::SplitInput in;
  if (auto built = build_base_level(mesh, options, ws, in.mesh); !built) return built;
  in.colors = mesh.colors.empty() ? nullptr : mesh.colors.data();
  in.texcoords = mesh.texcoords.empty() ? nullptr : mesh.texcoords.data();
  in.weights = &ws.weights;
  in.placement = options.rule == ButterflyRule::kProjection ? asa::EdgePlacement::kProjection
                                                            : asa::EdgePlacement::kZorin;
  // Per-corner attributes and face materials need every output face's
  // source and every new vertex's parents (corner_attributes.h).
  const bool corner_data = asa::has_corner_data(mesh);
  if (options.track_source_faces || corner_data) {
    ws.identity.resize(F);
    for (uint32_t f = 0; f < F; ++f) ws.identity[f] = f;
    in.source = ws.identity.data();
  }
  if (options.levels == 0 || F == 0) {
    result.mesh = mesh;
    result.face_kind.assign(F, FaceKind::kUntouched);
    if (options.track_source_faces)
      result.source_face = ws.identity;
    else
      result.source_face.clear();
    return {};
  }

  const bool normals = !mesh.normals.empty();
  // Carries the corner data onto the result (and drops the source faces
  // when only they needed them).
  auto finish = [&]() {
    // Mesh-wide: the materials and the images they use.
    result.mesh.materials = mesh.materials;
    result.mesh.textures = mesh.textures;
    if (!corner_data) {  // nothing of an earlier call's result stays
      result.mesh.corner_normals = {};
      result.mesh.corner_colors = {};
      result.mesh.corner_texcoords = {};
      result.mesh.face_materials.clear();
      return;
    }
    asa::carry_corner_attributes(mesh, result.source_face, ws.parents, result.mesh);
    if (!options.track_source_faces) result.source_face.clear();
  };
  for (int level = 0; level < options.levels; ++level) {
    const bool last = level + 1 == options.levels;
    asa::LevelMesh& out = ws.levels[level % 2];
    in.want_topology = !last;
    in.normals = nullptr;
    if (corner_data) {
      // Every edge may get a vertex: at most 3 per face.
      ws.parents.resize(2 * (size_t(in.mesh.vertex_count) + 3 * size_t(in.mesh.face_count)));
      in.parents = ws.parents.data();
    }
    std::vector<FaceKind>* kinds = last ? &result.face_kind : nullptr;
    if (options.uniform) {
      asa::split_uniform(in, ws.scratch, out, kinds);
      ws.stats.targets.push_back(in.mesh.face_count);
      ws.stats.split_edges.push_back(static_cast<uint32_t>(out.positions.size()) -
                                     in.mesh.vertex_count);
    } else if (!split_adaptive_level(level, options, camera ? &*camera : nullptr, in, ws, out,
                                     kinds)) {
      // Nothing bends: this and every later level would copy the mesh
      // unchanged (same normals, same verdicts). Stop here.
      copy_level_unchanged(in, normals, result);
      for (int rest = level; rest < options.levels; ++rest) {
        ws.stats.targets.push_back(0);
        ws.stats.split_edges.push_back(0);
      }
      finish();
      return {};
    }
    if (!last)
      advance_to(out, options.uniform, ws, in);
    else
      take_last_level(out, in.source != nullptr, normals, result);
  }
  finish();
  return {};
}

Result<AsaResult> subdivide(const Mesh& mesh, const AsaOptions& options, AsaWorkspace& workspace) {
  AsaResult result;
  if (auto ok = subdivide_into(mesh, options, workspace, result); !ok)
    return tl::unexpected(ok.error());
  return result;
}

Result<AsaResult> subdivide(const Mesh& mesh, const AsaOptions& options) {
  AsaWorkspace workspace;
  return subdivide(mesh, options, workspace);
}

}  // namespace meshstream
