// `meshstream generate NAME -o OUT [--size N]`: writes a procedural mesh
// (common/mesh/procedural.h) for demos, tests and benchmarks.
#include <cstdio>
#include <memory>
#include <string>

#include "common/mesh/export.h"
#include "common/mesh/procedural.h"
#include "tools/commands.h"

namespace meshstream::tools {
namespace {

struct GenerateArgs {
  std::string name;
  std::string output;
  int64_t size = -1;  // -1: the shape's default
  bool ascii = false;
};

Result<Mesh> make(const GenerateArgs& args) {
  auto size_or = [&args](uint32_t fallback) {
    return args.size < 0 ? fallback : static_cast<uint32_t>(args.size);
  };
  if (args.name == "demo") return make_demo_mesh(size_or(100000));
  if (args.name == "icosahedron") return make_icosahedron();
  if (args.name == "icosphere") return make_icosphere(size_or(4));
  if (args.name == "grid") return make_open_grid(size_or(32));
  if (args.name == "components") return make_multi_component(size_or(5));
  if (args.name == "torus") {
    const uint32_t minor = size_or(24);
    return make_torus(2 * minor, minor);
  }
  return make_error(ErrorCode::kInvalidArgument, "unknown shape '" + args.name + "'");
}

}  // namespace

void add_generate_command(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("generate", "Write a procedural mesh (demo model, test shapes)");
  auto args = std::make_shared<GenerateArgs>();
  cmd->add_option("name", args->name,
                  "demo (trefoil knot with detail at several scales), icosahedron, icosphere, grid "
                  "(open, one boundary), components (several closed parts), torus (genus 1)")
      ->required()
      ->check(CLI::IsMember({"demo", "icosahedron", "icosphere", "grid", "components", "torus"}));
  cmd->add_option("-o,--output", args->output,
                  "output file (.ply, .obj, .off, .stl, .glb or .gltf)")
      ->required()
      ->check(mesh_output_validator());
  cmd->add_option("--size", args->size,
                  "demo: target triangles (default 100000, up to 67M); icosphere: subdivisions "
                  "(default 4); grid: squares per side (32); components: count (5); torus: "
                  "segments around the tube (24)")
      ->check(CLI::Range(int64_t{1}, int64_t{1} << 26));
  cmd->add_flag("--ascii", args->ascii, "write ASCII PLY instead of binary");
  cmd->callback([args, &exit_code] {
    auto mesh = make(*args);
    if (!mesh) {
      exit_code = report_failure(mesh.error());
      return;
    }
    const bool ply =
        args->output.size() >= 4 && args->output.compare(args->output.size() - 4, 4, ".ply") == 0;
    Status written = ply && args->ascii ? write_ply(*mesh, args->output, PlyEncoding::kAscii)
                                        : write_mesh(*mesh, args->output);
    if (!written) {
      exit_code = report_failure(written.error());
      return;
    }
    std::printf("%s: %s, %u vertices, %u triangles\n", args->output.c_str(), args->name.c_str(),
                mesh->vertex_count(), mesh->face_count());
    exit_code = 0;
  });
}

}  // namespace meshstream::tools
