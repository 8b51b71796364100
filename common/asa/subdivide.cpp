// ASA driver: levels of flatness marking, closure and splitting (Cheang 1998,
// docs/algorithms.md section 3), or uniform modified Butterfly levels.
#include "common/asa/subdivide.h"

#include <cmath>
#include <cstring>
#include <string>
#include <utility>

#include "common/asa/butterfly_stencils.h"
#include "common/asa/closure.h"
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
  return {};
}

}  // namespace

Status subdivide_into(const Mesh& mesh, const AsaOptions& options, AsaWorkspace& workspace,
                      AsaResult& result) {
  if (auto ok = check_options(options); !ok) return ok;
  if (auto ok = validate_arrays(mesh); !ok) return ok;
  // Levels multiply faces by up to 4 each; refuse what cannot be indexed.
  const double projected = static_cast<double>(mesh.face_count()) * std::pow(4.0, options.levels);
  if (projected > 1.0e9) {
    return make_error(ErrorCode::kLimit, "subdividing " + std::to_string(mesh.face_count()) +
                                             " faces " + std::to_string(options.levels) +
                                             " times exceeds 1e9 faces");
  }

  AsaWorkspace::Buffers& ws = workspace.buffers();
  ws.scratch.points.fans_valid = false;  // a new input: fans are walked again
  ws.stats.targets.clear();
  ws.stats.split_edges.clear();
  const uint32_t F = mesh.face_count(), V = mesh.vertex_count();

  // Level 0: the caller's arrays plus our corner table and feature flags.
  asa::LevelMesh& base = ws.base;
  if (auto built = asa::build_opposites(mesh, base.opposite, base.across, ws.corner_scratch);
      !built)
    return built;
  asa::LevelView view;
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
  ws.weights.configure(options.tension);
  ws.weights.add_valences(base.valence.data(), base.vertex_features.data(), V);

  const Vec4f* colors = mesh.colors.empty() ? nullptr : mesh.colors.data();
  const Vec2f* texcoords = mesh.texcoords.empty() ? nullptr : mesh.texcoords.data();
  const asa::EdgePlacement placement = options.rule == ButterflyRule::kProjection
                                           ? asa::EdgePlacement::kProjection
                                           : asa::EdgePlacement::kZorin;

  const uint32_t* source = nullptr;
  if (options.track_source_faces) {
    ws.identity.resize(F);
    for (uint32_t f = 0; f < F; ++f) ws.identity[f] = f;
    source = ws.identity.data();
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

  for (int level = 0; level < options.levels; ++level) {
    const bool last = level + 1 == options.levels;
    asa::LevelMesh& out = ws.levels[level % 2];
    asa::SplitInput in;
    in.mesh = view;
    in.colors = colors;
    in.texcoords = texcoords;
    in.weights = &ws.weights;
    in.placement = placement;
    in.want_topology = !last;
    in.source = source;
    std::vector<FaceKind>* kinds = last ? &result.face_kind : nullptr;
    if (options.uniform) {
      asa::split_uniform(in, ws.scratch, out, kinds);
      ws.stats.targets.push_back(view.face_count);
      ws.stats.split_edges.push_back(static_cast<uint32_t>(out.positions.size()) -
                                     view.vertex_count);
    } else {
      // Level 0 tests every edge; later levels only the edges of faces the
      // last split made (their normals came with the split), unless most
      // faces are new anyway.
      const bool mostly_fresh =
          level > 0 && 2 * static_cast<uint64_t>(ws.scratch.fresh_count) > view.face_count;
      const uint32_t targets =
          level == 0 || mostly_fresh
              ? asa::mark_targets(view, ws.normals, options.flatness, ws.target)
              : asa::mark_targets_near_fresh(view, ws.normals, ws.fresh, options.flatness,
                                             ws.target);
      if (targets == 0) {
        // Nothing bends: this and every later level would copy the mesh
        // unchanged (same normals, same verdicts). Stop here.
        const size_t V = view.vertex_count, F = view.face_count;
        result.mesh.positions.assign(view.positions, view.positions + V);
        result.mesh.triangles.resize(F);
        if (F) std::memcpy(result.mesh.triangles.data(), view.corner_vertex, F * sizeof(Triangle));
        if (colors)
          result.mesh.colors.assign(colors, colors + V);
        else
          result.mesh.colors.clear();
        if (texcoords)
          result.mesh.texcoords.assign(texcoords, texcoords + V);
        else
          result.mesh.texcoords.clear();
        result.face_kind.assign(F, FaceKind::kUntouched);
        if (source)
          result.source_face.assign(source, source + F);
        else
          result.source_face.clear();
        if (!mesh.normals.empty())
          result.mesh.normals = compute_vertex_normals(result.mesh);
        else
          result.mesh.normals.clear();
        for (int rest = level; rest < options.levels; ++rest) {
          ws.stats.targets.push_back(0);
          ws.stats.split_edges.push_back(0);
        }
        return {};
      }
      const uint32_t split = asa::close_targets(view, ws.target.data(), ws.closure);
      in.normals = ws.normals.data();
      asa::split_adaptive(in, ws.closure, ws.scratch, out, kinds);
      if (!last) {
        std::swap(ws.normals, out.normals);
        std::swap(ws.fresh, out.fresh);
      }
      ws.stats.targets.push_back(targets);
      ws.stats.split_edges.push_back(split);
    }
    if (!last) {
      if (!options.uniform) {
        // Bisections change valences (the split counted them): add any new
        // ones, looking only at new vertices and those of replaced faces.
        ws.weights.add_valences(out.valence.data(), out.vertex_features.data(), ws.scratch.touched);
        ws.weights.add_valences(out.valence.data(), out.vertex_features.data(), view.vertex_count,
                                static_cast<uint32_t>(out.valence.size()) - view.vertex_count);
      }
      view = out.view();
      if (source) source = out.source.data();
      colors = out.colors.empty() ? nullptr : out.colors.data();
      texcoords = out.texcoords.empty() ? nullptr : out.texcoords.data();
    } else {
      std::swap(result.mesh.positions, out.positions);
      std::swap(result.mesh.triangles, out.triangles);
      std::swap(result.mesh.colors, out.colors);
      std::swap(result.mesh.texcoords, out.texcoords);
      if (source)
        std::swap(result.source_face, out.source);
      else
        result.source_face.clear();
      if (!mesh.normals.empty()) {
        result.mesh.normals = compute_vertex_normals(result.mesh);
      } else {
        result.mesh.normals.clear();
      }
    }
  }
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
