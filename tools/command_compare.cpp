// `meshstream compare A B [--json]`: how far apart two surfaces are.
// Symmetric Hausdorff and RMS distance (common/metrics/distance.h), absolute
// and relative to A's bounding-box diagonal.
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>

#include "common/mesh/import.h"
#include "common/metrics/distance.h"
#include "tools/commands.h"

namespace meshstream::tools {
namespace {

struct CompareArgs {
  std::string a, b;
  bool json = false;
  uint32_t samples = DistanceOptions{}.samples;
  uint64_t seed = DistanceOptions{}.seed;
};

// Analysis-mode import: weld and drop unreferenced vertices, but repair and
// reorder nothing, so the distance is between the files as drawn. Faces
// folded flat (12-bit quantization folds many on dense scans; a one-face
// component can fold to a point) stay: welding makes them repeat a vertex,
// and dropping them would make a correct decode look as if whole components
// were missing. The metrics measure such a face as its segment or point.
Result<Mesh> load(const std::string& path) {
  ImportOptions options;
  options.keep_nonmanifold = true;
  options.keep_degenerate_faces = true;
  options.drop_duplicate_faces = false;
  auto imported = import_mesh(path, options);
  if (!imported) return tl::unexpected(imported.error());
  return std::move(imported->mesh);
}

nlohmann::json one_sided_json(const OneSidedDistance& d) {
  return {{"max", d.max}, {"mean", d.mean}, {"rms", d.rms}};
}

std::string percent(double relative) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.4g %%", 100 * relative);
  return buffer;
}

int run_compare(const CompareArgs& args) {
  auto a = load(args.a);
  if (!a) return report_failure(a.error());
  auto b = load(args.b);
  if (!b) return report_failure(b.error());
  DistanceOptions options;
  options.samples = args.samples;
  options.seed = args.seed;
  auto d = surface_distance(*a, *b, options);
  if (!d) return report_failure(std::move(d.error()).with_context(args.a + " vs " + args.b));

  if (args.json) {
    nlohmann::json out = {
        {"a", {{"path", args.a}, {"vertices", a->vertex_count()}, {"faces", a->face_count()}}},
        {"b", {{"path", args.b}, {"vertices", b->vertex_count()}, {"faces", b->face_count()}}},
        {"hausdorff", d->hausdorff},
        {"rms", d->rms},
        {"diagonal", d->diagonal},
        {"relative_hausdorff", d->relative_hausdorff()},
        {"relative_rms", d->relative_rms()},
        {"a_to_b", one_sided_json(d->a_to_b)},
        {"b_to_a", one_sided_json(d->b_to_a)},
        {"samples", args.samples},
        {"seed", args.seed}};
    std::cout << out.dump() << "\n";
    return 0;
  }
  std::printf("A: %s (%u vertices, %u faces)\n", args.a.c_str(), a->vertex_count(),
              a->face_count());
  std::printf("B: %s (%u vertices, %u faces)\n", args.b.c_str(), b->vertex_count(),
              b->face_count());
  std::printf("A's bounding-box diagonal: %.9g\n", d->diagonal);
  std::printf("Hausdorff: %.9g (%s of the diagonal)\n", d->hausdorff,
              percent(d->relative_hausdorff()).c_str());
  std::printf("RMS:       %.9g (%s of the diagonal)\n", d->rms, percent(d->relative_rms()).c_str());
  std::printf("A to B:    max %.9g  mean %.9g  rms %.9g\n", d->a_to_b.max, d->a_to_b.mean,
              d->a_to_b.rms);
  std::printf("B to A:    max %.9g  mean %.9g  rms %.9g\n", d->b_to_a.max, d->b_to_a.mean,
              d->b_to_a.rms);
  std::printf("(%u area samples per direction plus every vertex and edge midpoint, seed %llu)\n",
              args.samples, static_cast<unsigned long long>(args.seed));
  return 0;
}

}  // namespace

void add_compare_command(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<CompareArgs>();
  auto* cmd = app.add_subcommand(
      "compare",
      "Symmetric Hausdorff and RMS surface distance between two meshes, absolute and relative "
      "to A's bounding-box diagonal");
  cmd->add_option("A", args->a,
                  "first mesh (OBJ, PLY, STL, OFF, DRC, glTF, GLB); its diagonal is the scale")
      ->required();
  cmd->add_option("B", args->b, "second mesh")->required();
  cmd->add_flag("--json", args->json, "one JSON object on stdout");
  cmd->add_option("--samples", args->samples,
                  "area samples per direction (vertices and edge midpoints are added)")
      ->check(CLI::Range(0u, 50000000u))
      ->capture_default_str();
  cmd->add_option("--seed", args->seed, "sampling seed (results are deterministic for a seed)")
      ->capture_default_str();
  cmd->callback([args, &exit_code] { exit_code = run_compare(*args); });
}

}  // namespace meshstream::tools
