// Off-screen rendering without any display: an OSMesa (Mesa's software
// rasterizer) OpenGL 3.3 core context drives the same MeshRenderer as the
// window, so snapshots look exactly like what the viewer shows.
#pragma once

#include <optional>
#include <vector>

#include "client/viewer/mesh_renderer.h"
#include "client/viewer/rgba_image.h"
#include "common/asa/subdivide.h"
#include "common/base/result.h"
#include "common/mesh/mesh.h"

namespace meshstream::client {

struct OffscreenRequest {
  int width = 1024;
  int height = 768;
  RenderStyle style;
  const std::vector<FaceKind>* face_kind = nullptr;     // per face, for kAsaKinds
  const std::vector<float>* vertex_distance = nullptr;  // per vertex, for kDistance
  // Normals split where faces bend more than this (the user's --crease; 0:
  // kDefaultShadingCreaseDegrees), see crease_normals.h.
  float crease_degrees = 0.0f;
  int samples = 4;     // multisampling
  float fill = 0.85f;  // share of the smaller image side the model spans
  // When set, the camera frames this mesh instead of the one drawn, so that
  // several meshes (a prefix, its ASA, the full model) share one camera; with
  // `camera`, it sets the near and far planes (a culled mesh is drawn with
  // the planes of the whole one, so its depths are the same).
  const Mesh* frame_on = nullptr;
  // Viewing direction (radians); the distance and target frame the model.
  float yaw = 0.6f;
  float pitch = 0.35f;
  // When set, this camera instead of the framing (the one view-dependent
  // ASA refined for, so the picture matches the refinement).
  std::optional<AsaCamera> camera;
};

// Renders `mesh` framed as a whole (OrbitCamera::frame), or seen by
// request.camera, into an image.
// kInvalidMesh when the mesh breaks validate_arrays; kInvalidArgument for a
// size outside 1..8192 or the GL limit; kUnsupported when OSMesa cannot make
// a 3.3 core context. Calls are serialized (one context at a time). Cost:
// context creation (~ms) plus software rasterization, about O(pixels + F).
Result<RgbaImage> render_offscreen(const Mesh& mesh, const OffscreenRequest& request);

}  // namespace meshstream::client
