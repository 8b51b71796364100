// render_snapshot (viewer.h): the off-screen renderer plus a PNG file.
#include "client/viewer/offscreen.h"
#include "client/viewer/viewer.h"

namespace meshstream::client {

Status render_snapshot(const Mesh& mesh, const std::vector<FaceKind>* face_kind,
                       const SnapshotOptions& options, const std::string& png_path) {
  OffscreenRequest request;
  request.width = options.width;
  request.height = options.height;
  request.style.coloring = options.coloring == SnapshotOptions::Coloring::kAsaKinds
                               ? ColorMode::kAsaKinds
                               : ColorMode::kShaded;
  request.style.wireframe = options.wireframe;
  request.face_kind = face_kind;
  request.crease_degrees = options.crease_degrees;
  request.camera = options.camera;
  request.frame_on = options.frame_on;
  auto image = render_offscreen(mesh, request);
  if (!image) return tl::unexpected(std::move(image.error()).with_context(png_path));
  return write_png(png_path, *image);
}

}  // namespace meshstream::client
