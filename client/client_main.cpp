// meshstream-client: parse options -> stream (network thread, display
// pipeline thread, viewer or snapshots on this one) -> report -> exit code.
#include <variant>

#include "client/client_app.h"
#include "client/client_options.h"
#include "client/viewer/viewer.h"

using namespace meshstream::client;

int main(int argc, char** argv) {
  ParsedClientOptions parsed = parse_client_options(argc, argv);
  if (const int* exit_code = std::get_if<int>(&parsed)) return *exit_code;
  const ClientOptions& options = std::get<ClientOptions>(parsed);

  ViewerHooks hooks;
  hooks.run_view = [](const ClientOptions& o, LatestFrameMailbox& frames,
                      StreamControls& controls) {
    ViewerOptions v;
    v.width = o.width;
    v.height = o.height;
    v.title = "meshstream - " + o.model;
    v.exit_after_frames = o.exit_after_frames;
    v.exit_after_records = o.exit_after_records;
    return run_viewer(v, frames, controls);
  };
  hooks.snapshot = [](const meshstream::Mesh& mesh, const std::vector<meshstream::FaceKind>* kinds,
                      const meshstream::Mesh& whole, const meshstream::AsaCamera* camera,
                      const ClientOptions& o, const std::string& png) {
    SnapshotOptions s;
    if (camera) s.camera = *camera;
    s.width = o.width;
    s.height = o.height;
    s.crease_degrees = o.asa.crease_degrees;
    s.frame_on = &whole;
    return render_snapshot(mesh, kinds, s, png);
  };
  return run_client(options, hooks);
}
