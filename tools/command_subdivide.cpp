// `meshstream subdivide IN -o OUT [--levels L] [--flatness T] [--uniform]
//  [--rule zorin|projection] [--crease DEG] [--tension W]
//  [--camera EX,EY,EZ,TX,TY,TZ[,FOV] [--pixel-tolerance PX] [--width W --height H]]`:
// ASA (adaptive modified Butterfly, common/asa/subdivide.h) on a mesh file.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <string>

#include "common/asa/settings_check.h"
#include "common/asa/subdivide.h"
#include "common/mesh/export.h"
#include "common/mesh/import.h"
#include "tools/commands.h"

namespace meshstream::tools {
namespace {

struct SubdivideArgs {
  std::string input, output;
  AsaOptions options;
  std::string rule = "zorin";
  std::string camera;  // view-dependent ASA when set
  float pixel_tolerance = 2;
  int width = 1024, height = 768;
};

// --camera and its companions into options.view; the exit code 2 after a
// usage error (printed), else 0.
int set_view(SubdivideArgs& args) {
  auto usage = [](const std::string& why) {
    std::fprintf(stderr, "meshstream subdivide: %s (see --help)\n", why.c_str());
    return 2;
  };
  if (args.camera.empty()) return 0;
  AsaView& view = args.options.view;
  if (auto parsed = parse_camera(args.camera, view.camera); !parsed)
    return usage(parsed.error().message);
  if (!(args.pixel_tolerance > 0) || !std::isfinite(args.pixel_tolerance)) {
    char text[64];
    std::snprintf(text, sizeof text, "%g", args.pixel_tolerance);
    return usage(std::string("--pixel-tolerance ") + text + ": must be above 0 pixels");
  }
  if (args.options.uniform) return usage("--camera needs ASA: it cannot go with --uniform");
  view.enabled = true;
  view.camera.width = args.width;
  view.camera.height = args.height;
  view.pixel_tolerance = args.pixel_tolerance;
  return 0;
}

int run_subdivide(SubdivideArgs& args) {
  auto imported = import_mesh(args.input);
  if (!imported) return report_failure(imported.error());
  const Mesh& mesh = imported->mesh;
  if (args.options.view.enabled) args.options.view.facing_sign = facing_sign_of(mesh);
  args.options.rule =
      args.rule == "projection" ? ButterflyRule::kProjection : ButterflyRule::kZorin;

  const auto start = std::chrono::steady_clock::now();
  AsaWorkspace workspace;
  auto result = subdivide(mesh, args.options, workspace);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (!result) return report_failure(std::move(result.error()).with_context(args.input));

  if (auto written = write_mesh(result->mesh, args.output); !written) {
    return report_failure(std::move(written.error()).with_context(args.output));
  }
  for (const std::string& lost : export_losses(result->mesh, args.output))
    std::fprintf(stderr, "meshstream subdivide: %s: warning: not stored: %s\n", args.output.c_str(),
                 lost.c_str());
  std::map<FaceKind, uint32_t> kinds;
  for (FaceKind k : result->face_kind) ++kinds[k];
  std::printf(
      "%s: %u vertices, %u faces -> %s: %u vertices, %u faces (%s, %d level%s, %.1f ms)\n",
      args.input.c_str(), mesh.vertex_count(), mesh.face_count(), args.output.c_str(),
      result->mesh.vertex_count(), result->mesh.face_count(),
      args.options.uniform ? "uniform" : ("ASA t=" + std::to_string(args.options.flatness)).c_str(),
      args.options.levels, args.options.levels == 1 ? "" : "s", ms);
  if (args.options.view.enabled)
    std::printf("  camera %s at %dx%d, pixel tolerance %g\n",
                format_camera(args.options.view.camera).c_str(), args.width, args.height,
                args.options.view.pixel_tolerance);
  if (!args.options.uniform) {
    const AsaStats& stats = workspace.last_stats();
    for (size_t level = 0; level < stats.targets.size(); ++level) {
      std::printf("  level %zu: %u flatness targets, %u new vertices\n", level + 1,
                  stats.targets[level], stats.split_edges[level]);
    }
    std::printf("  last level: %u faces split 1-to-4, %u bisected, %u untouched\n",
                kinds[FaceKind::kTarget], kinds[FaceKind::kBisected], kinds[FaceKind::kUntouched]);
  }
  return 0;
}

}  // namespace

void add_subdivide_command(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<SubdivideArgs>();
  auto* cmd = app.add_subcommand(
      "subdivide",
      "Adaptive modified-Butterfly subdivision (ASA): refine where neighbouring triangles bend, "
      "or everywhere with --uniform. Old vertices never move.");
  cmd->add_option("IN", args->input, "input mesh (OBJ, PLY, STL, OFF, DRC, glTF, GLB)")->required();
  cmd->add_option("-o,--output", args->output,
                  "output mesh (.ply, .obj, .off, .stl, .glb or .gltf)")
      ->required()
      ->check(mesh_output_validator());
  cmd->add_option("--levels", args->options.levels,
                  "subdivision levels (flatness re-evaluated each)")
      ->check(CLI::Range(0, 8))
      ->capture_default_str();
  cmd->add_option(
         "--flatness", args->options.flatness,
         "t: triangles whose normals differ by more than acos(t) are refined (0.7-0.9 works well)")
      ->check(CLI::Range(-1.0f, 1.0f))
      ->capture_default_str();
  cmd->add_flag("--uniform", args->options.uniform,
                "split every triangle (classic modified Butterfly)");
  cmd->add_option("--rule", args->rule,
                  "zorin: weights on 3-D points; projection: only the normal offset (thesis)")
      ->check(CLI::IsMember({"zorin", "projection"}))
      ->capture_default_str();
  cmd->add_option("--crease", args->options.crease_degrees,
                  "edges bending more than DEG degrees stay sharp (0 = off); without --uniform, "
                  "DEG below acos(--flatness) (31.8 at t = 0.85) is refused: every edge ASA "
                  "refines would stay sharp")
      ->check(CLI::Range(0.0f, 180.0f))
      ->capture_default_str();
  cmd->add_option("--tension", args->options.tension, "omega of the ten-point stencil")
      ->check(CLI::Range(-0.25f, 0.25f))
      ->capture_default_str();
  cmd->add_option("--camera", args->camera,
                  "EX,EY,EZ,TX,TY,TZ[,FOV_DEG]: view-dependent ASA for this camera (eye, target, "
                  "vertical field of view, default 45): a bent edge is split only where it is in "
                  "view, not back-facing and projects above --pixel-tolerance (default: the whole "
                  "mesh)");
  cmd->add_option("--pixel-tolerance", args->pixel_tolerance,
                  "with --camera: edges projecting to PX pixels or less stay")
      ->capture_default_str();
  cmd->add_option("--width", args->width, "with --camera: image width in pixels")
      ->check(CLI::Range(16, 16384))
      ->capture_default_str();
  cmd->add_option("--height", args->height, "with --camera: image height in pixels")
      ->check(CLI::Range(16, 16384))
      ->capture_default_str();
  cmd->callback([args, &exit_code] {
    // Settings that cancel each other are a usage error (exit 2, like a bad value).
    if (std::string clash = asa_settings_problem(args->options, "--crease", "--flatness");
        !clash.empty())
      throw CLI::ValidationError("subdivide", clash);
    exit_code = set_view(*args);
    if (exit_code == 0) exit_code = run_subdivide(*args);
  });
}

}  // namespace meshstream::tools
