// The whole `meshstream-client` run: list, or stream with the network
// thread + display pipeline thread, and report through events, snapshot
// files and (through hooks, so this library needs no OpenGL) the viewer.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "client/client_options.h"
#include "client/display_frame.h"
#include "common/base/result.h"

namespace meshstream::client {

// Entry points of the viewer library, passed in by the executable.
struct ViewerHooks {
  // Runs the window on the calling (main) thread until it closes.
  std::function<Status(const ClientOptions&, LatestFrameMailbox&, StreamControls&)> run_view;
  // Renders a display mesh (what the renderer is handed: the culled one in
  // view-dependent mode) to a PNG with the camera its display was made for
  // (null: framed on `whole`, the display mesh before the cull, which also
  // sets the near and far planes).
  std::function<Status(const Mesh& drawn, const std::vector<FaceKind>*, const Mesh& whole,
                       const AsaCamera*, const ClientOptions&, const std::string& png)>
      snapshot;
};

// Exit code: 0 ok, 1 server, stream or file error (message printed).
int run_client(const ClientOptions& options, const ViewerHooks& hooks);

}  // namespace meshstream::client
