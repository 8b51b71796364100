// View-dependent ASA (issue 16): the picture against whole-mesh ASA at the
// same camera (PSNR of off-screen snapshots), display faces against model
// size, ASA time per update as the client runs it (DisplayBuilder, one
// update per record), and camera moves on a big decoded mesh.
// Writes bench/report/view_asa.md (or DIR/view_asa.md with --report-dir).
//
// Usage: view_asa_bench [--report-dir DIR] [--meshes a,b] [--big FILE[,FILE]]
//                       [--streams DIR] [--no-big-pictures] [--updates-only]
//                       [--pixel-tolerance PX] [--no-orbit] [--no-updates]
//                       [--orbit-steps N] [--no-orbit-cull]
// --big: large PLY files (read only), measured on the full mesh; an HCS of
// the same stem in --streams DIR adds its early and middle prefixes.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "bench/real_mesh_list.h"
#include "client/display_builder.h"
#include "client/viewer/image_psnr.h"
#include "client/viewer/offscreen.h"
#include "common/asa/display_cull.h"
#include "common/asa/incremental.h"
#include "common/asa/view.h"
#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "common/mesh/import.h"
#include "tests/test_meshes.h"

using namespace meshstream;
using namespace meshstream::client;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

// This thread's CPU time: on a machine shared by many jobs the wall clock
// mostly measures the others; both are reported.
double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

float g_tolerance = 2;     // --pixel-tolerance
int g_orbit_steps = 10;    // --orbit-steps
bool g_orbit_cull = true;  // --no-orbit-cull: the orbit measures ASA only
CullMargins g_margins;     // --cull-eye-share, --cull-angle

AsaOptions view_options(const Mesh& mesh, const AsaCamera& camera) {
  AsaOptions o;  // the client's defaults: 1 level, t = 0.85, tolerance 2 px
  o.view.enabled = true;
  o.view.pixel_tolerance = g_tolerance;
  o.view.camera = camera;
  o.view.facing_sign = facing_sign_of(mesh);
  return o;
}

struct Prefix {
  std::string name;  // early, middle, full
  Mesh mesh;
};

// The decoded mesh after 10 %, 50 % and 100 % of the records (full only
// without a stream).
std::vector<Prefix> prefixes(const Mesh& source, const std::vector<uint8_t>* stream) {
  std::vector<Prefix> out;
  if (stream == nullptr) {
    out.push_back({"full", source});
    return out;
  }
  IncrementalDecoder decoder;
  size_t at = 0;
  while (!decoder.index() && at < stream->size()) {
    const size_t end = std::min(stream->size(), at + 256);
    if (!decoder.feed(std::span<const uint8_t>(stream->data() + at, end - at))) return out;
    at = end;
  }
  if (!decoder.index()) return out;
  const auto& records = decoder.index()->records;
  const size_t n = records.size();
  const std::vector<std::pair<std::string, size_t>> picks{
      {"early", std::max<size_t>(1, n / 10)}, {"middle", std::max<size_t>(1, n / 2)}, {"full", n}};
  for (const auto& [name, count] : picks) {
    const size_t end = static_cast<size_t>(records[count - 1].offset + records[count - 1].size);
    if (end > at) {
      if (!decoder.feed(std::span<const uint8_t>(stream->data() + at, end - at))) return out;
      at = end;
    }
    out.push_back({name, decoder.mesh()});
  }
  return out;
}

struct PictureRow {
  std::string mesh, prefix;
  uint32_t faces = 0, vi_faces = 0, vd_faces = 0;
  double psnr = 0, vi_ms = 0, vd_ms = 0;
  // The renderer's cull of the view-dependent display (display_cull.h):
  // faces handed to the renderer, its cost (topology + cull), and its
  // picture against the unculled one (inf: the same pixels).
  uint32_t drawn_faces = 0;
  double cull_ms = 0, cull_psnr = 0;
  double decoded_psnr = 0;  // the plain decoded mesh against whole-mesh ASA
  bool with_pictures = true;
};

Result<RgbaImage> snapshot(const Mesh& mesh, const AsaCamera& camera,
                           const Mesh* frame_on = nullptr) {
  OffscreenRequest request;
  request.width = camera.width;
  request.height = camera.height;
  request.camera = camera;
  request.frame_on = frame_on;
  return render_offscreen(mesh, request);
}

PictureRow picture_row(const std::string& name, const Prefix& p, int width, int height,
                       bool with_pictures = true) {
  PictureRow row;
  row.with_pictures = with_pictures;
  row.mesh = name;
  row.prefix = p.name;
  row.faces = p.mesh.face_count();
  const AsaCamera camera = fit_camera(p.mesh, width, height);
  AsaOptions vi;  // whole mesh
  AsaOptions vd = view_options(p.mesh, camera);
  AsaWorkspace ws;
  auto t0 = Clock::now();
  auto a = subdivide(p.mesh, vi, ws);
  row.vi_ms = ms_since(t0);
  t0 = Clock::now();
  auto b = subdivide(p.mesh, vd, ws);
  row.vd_ms = ms_since(t0);
  if (!a || !b) return row;
  row.vi_faces = a->mesh.face_count();
  row.vd_faces = b->mesh.face_count();
  auto display = std::make_shared<const Mesh>(std::move(b->mesh));
  t0 = Clock::now();
  const auto topology = analyze_display_topology(*display, *analyze_source_topology(p.mesh));
  const CulledDisplay culled = cull_display(display, nullptr, *topology, camera, 0, g_margins);
  row.cull_ms = ms_since(t0);
  row.drawn_faces = culled.mesh->face_count();
  if (row.with_pictures) {
    auto ia = snapshot(a->mesh, camera);
    auto ib = snapshot(*display, camera);
    if (ia && ib) row.psnr = psnr_rgb(*ia, *ib);
    auto ic = snapshot(*culled.mesh, camera, display.get());
    if (ib && ic) row.cull_psnr = psnr_rgb(*ib, *ic);
    auto id = snapshot(p.mesh, camera);
    if (ia && id) row.decoded_psnr = psnr_rgb(*ia, *id);
  }
  std::fprintf(stderr,
               "picture %s %s: %u faces, vi %u vd %u drawn %u (cull %.1f ms), %.1f dB, cull %.1f "
               "dB, decoded vs vi %.1f dB\n",
               name.c_str(), p.name.c_str(), row.faces, row.vi_faces, row.vd_faces, row.drawn_faces,
               row.cull_ms, row.psnr, row.cull_psnr, row.decoded_psnr);
  return row;
}

// One update per record through the client's DisplayBuilder, the snapshot
// camera fitted on each update's mesh (as the pipeline does).
struct UpdateStats {
  std::vector<double> asa_ms;                     // per update with decoded faces <= max_faces
  std::vector<double> vi_asa_ms;                  // the same, view-independent
  std::vector<double> asa_cpu_ms, vi_asa_cpu_ms;  // the same in CPU time
  // The view-dependent update's parts: the snapshot camera fit and the
  // facing sign (the pipeline's, outside asa_ms), and the builder's ASA.
  std::vector<double> camera_ms, build_ms;
  uint32_t largest_faces = 0;
};

// One update per record. With `whole_mesh` false (the big models), only
// the view-dependent builder runs, and only updates of decoded meshes
// above `from_faces` faces are timed (the decoder still applies every record).
void replay(const std::vector<uint8_t>& stream, UpdateStats& stats, uint32_t max_faces = 1'000'000,
            bool whole_mesh = true, uint32_t from_faces = 0) {
  IncrementalDecoder decoder;
  size_t at = 0;
  while (!decoder.index() && at < stream.size()) {
    const size_t end = std::min(stream.size(), at + 256);
    if (!decoder.feed(std::span<const uint8_t>(stream.data() + at, end - at))) return;
    at = end;
  }
  if (!decoder.index()) return;
  DisplayBuilder vd_builder, vi_builder;
  vd_builder.set_max_faces(4'000'000);
  vi_builder.set_max_faces(4'000'000);
  vd_builder.set_changes_exact(true);  // as the pipeline
  vi_builder.set_changes_exact(true);
  bool first = true;
  for (const RecordEntry& rec : decoder.index()->records) {
    const size_t end = static_cast<size_t>(rec.offset + rec.size);
    if (end <= at) continue;
    if (!decoder.feed(std::span<const uint8_t>(stream.data() + at, end - at))) return;
    at = end;
    if (decoder.mesh().face_count() > max_faces) break;
    auto mesh = std::make_shared<const Mesh>(decoder.mesh());
    stats.largest_faces = std::max(stats.largest_faces, mesh->face_count());
    MeshChanges changes;
    changes.full = first;
    for (const RecordDelta& d : decoder.last_deltas()) {
      // As the pipeline (decoded_stream.cpp): a plane record's moves are
      // no full rebuild.
      const bool moves_only =
          !d.moved_vertices.empty() && d.added_vertices.empty() && d.touched_faces.empty();
      changes.full |= d.full_rebuild && !moves_only;
      changes.vertices.insert(changes.vertices.end(), d.added_vertices.begin(),
                              d.added_vertices.end());
      changes.faces.insert(changes.faces.end(), d.touched_faces.begin(), d.touched_faces.end());
      changes.moved.insert(changes.moved.end(), d.moved_vertices.begin(), d.moved_vertices.end());
    }
    BuildReport report;
    auto t0 = Clock::now();
    double c0 = thread_cpu_ms();
    const AsaOptions vd = view_options(*mesh, fit_camera(*mesh, 1024, 768, /*snap=*/true));
    const double camera_ms = ms_since(t0);
    if (!vd_builder.build(mesh, changes, true, vd, first, report)) return;
    const bool timed = mesh->face_count() > from_faces;
    if (timed) {
      stats.asa_ms.push_back(ms_since(t0));  // with the camera fit, as the pipeline pays it
      stats.asa_cpu_ms.push_back(thread_cpu_ms() - c0);
      stats.camera_ms.push_back(camera_ms);
      stats.build_ms.push_back(report.asa_ms);
    }
    first = false;
    if (!whole_mesh) continue;
    c0 = thread_cpu_ms();
    if (!vi_builder.build(mesh, changes, true, AsaOptions{}, stats.vi_asa_ms.empty(), report))
      return;
    stats.vi_asa_ms.push_back(report.asa_ms);
    stats.vi_asa_cpu_ms.push_back(thread_cpu_ms() - c0);
  }
}

std::vector<uint8_t> encode(const Mesh& mesh) {
  auto stream = encode_hcs(mesh, EncodeOptions{});
  return stream ? *stream : std::vector<uint8_t>{};
}

std::vector<uint8_t> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

// Orbit steps of 2 degrees on a big decoded mesh through the client's
// DisplayBuilder, as the viewer drives it (a new camera, no mesh change):
// wall and CPU ms per step, the display mesh included.
struct OrbitStats {
  std::vector<double> ms, cpu_ms;
  std::vector<uint32_t> region_faces;
  // The pipeline's renderer cull after each step (topology + cull, O(F)).
  std::vector<double> cull_ms, cull_cpu_ms;
  std::vector<uint32_t> drawn_faces;
};

OrbitStats orbit(const Mesh& mesh, int width, int height, int steps) {
  const AsaCamera fit = fit_camera(mesh, width, height);
  AsaOptions o = view_options(mesh, fit);
  auto shared = std::make_shared<const Mesh>(mesh);
  DisplayBuilder builder;
  builder.set_max_faces(4'000'000);
  builder.set_changes_exact(true);  // as the pipeline: no change is no change
  OrbitStats out;
  BuildReport report;
  MeshChanges none;
  none.full = true;
  if (!builder.build(shared, none, true, o, true, report)) return out;
  none.full = false;
  const Vec3f offset = fit.eye - fit.target;
  const auto source = analyze_source_topology(mesh);
  for (int s = 1; s <= steps; ++s) {
    const float a = 2.0f * static_cast<float>(s) * 3.14159265f / 180.0f;
    AsaOptions step = o;
    step.view.camera.eye =
        fit.target + Vec3f{offset.x * std::cos(a) - offset.z * std::sin(a), offset.y,
                           offset.x * std::sin(a) + offset.z * std::cos(a)};
    const auto t0 = Clock::now();
    const double c0 = thread_cpu_ms();
    auto display = builder.build(shared, none, true, step, false, report);
    if (!display) break;
    out.ms.push_back(ms_since(t0));
    out.cpu_ms.push_back(thread_cpu_ms() - c0);
    out.region_faces.push_back(report.region_faces);
    if (!display || !g_orbit_cull) continue;
    const auto t1 = Clock::now();
    const double c1 = thread_cpu_ms();
    // The source's topology is the pipeline's once per decoded mesh.
    const auto topology = analyze_display_topology(*display->mesh, *source);
    const CulledDisplay culled =
        cull_display(display->mesh, display->face_kind, *topology, step.view.camera, 0, g_margins);
    out.cull_ms.push_back(ms_since(t1));
    out.cull_cpu_ms.push_back(thread_cpu_ms() - c1);
    out.drawn_faces.push_back(culled.mesh->face_count());
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  std::string report_dir = std::string(MESHSTREAM_SOURCE_DIR) + "/bench/report";
  std::vector<std::string> meshes = bench::kRealMeshes, big;
  std::string streams;
  bool big_pictures = true;     // --no-big-pictures: big models' face counts and orbit only
  bool pictures_wanted = true;  // --updates-only: per-update times and orbits, no pictures
  bool orbit_wanted = true;     // --no-orbit
  bool updates_wanted = true;   // --no-updates: no per-update replay
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--no-big-pictures") big_pictures = false;
    if (a == "--updates-only") pictures_wanted = false;
    if (a == "--report-dir" && i + 1 < argc) report_dir = argv[++i];
    if (a == "--meshes" && i + 1 < argc) meshes = bench::split_commas(argv[++i]);
    if (a == "--big" && i + 1 < argc) big = bench::split_commas(argv[++i]);
    if (a == "--streams" && i + 1 < argc) streams = argv[++i];
    if (a == "--pixel-tolerance" && i + 1 < argc) g_tolerance = std::stof(argv[++i]);
    if (a == "--no-orbit") orbit_wanted = false;
    if (a == "--cull-eye-share" && i + 1 < argc) g_margins.eye_share = std::stof(argv[++i]);
    if (a == "--cull-angle" && i + 1 < argc) g_margins.angle_degrees = std::stof(argv[++i]);
    if (a == "--no-updates") updates_wanted = false;
    if (a == "--orbit-steps" && i + 1 < argc) g_orbit_steps = std::stoi(argv[++i]);
    if (a == "--no-orbit-cull") g_orbit_cull = false;
  }
  std::vector<PictureRow> pictures, faces_rows;
  std::vector<std::pair<std::string, UpdateStats>> updates, big_updates;
  for (const std::string& name : meshes) {
    const std::string path = testing::test_mesh(name);
    auto imported = import_mesh(path);
    if (!imported) {
      std::fprintf(stderr, "skip %s: %s\n", name.c_str(), imported.error().message.c_str());
      continue;
    }
    const std::vector<uint8_t> stream = encode(imported->mesh);
    if (stream.empty()) continue;
    if (pictures_wanted) {
      for (const Prefix& p : prefixes(imported->mesh, &stream))
        pictures.push_back(picture_row(name, p, 1024, 768));
      const Prefix full{"full", *decode_hcs(stream)};
      faces_rows.push_back(picture_row(name, full, 1280, 720));
    }
    if (!updates_wanted) continue;
    UpdateStats stats;
    replay(stream, stats);
    updates.emplace_back(name, stats);
  }
  std::vector<std::pair<std::string, OrbitStats>> orbits;
  for (const std::string& path : big) {
    auto imported = import_mesh(path);
    if (!imported) continue;
    const std::string name = fs::path(path).filename().string();
    std::vector<uint8_t> stream;
    const std::string hcs = streams + "/" + fs::path(path).stem().string() + ".hcs";
    if (!streams.empty() && fs::exists(hcs)) stream = read_bytes(hcs);
    if (big_pictures && pictures_wanted) {
      for (const Prefix& p : prefixes(imported->mesh, stream.empty() ? nullptr : &stream))
        pictures.push_back(picture_row(name, p, 1024, 768));
    }
    if (pictures_wanted)
      faces_rows.push_back(picture_row(name, {"full", imported->mesh}, 1280, 720, big_pictures));
    if (!stream.empty() && updates_wanted) {
      // The big model's updates in the second half of its faces, as the
      // client's pipeline runs them (view-dependent only).
      UpdateStats stats;
      replay(stream, stats, ~0u, /*whole_mesh=*/false, imported->mesh.face_count() / 2);
      big_updates.emplace_back(name, stats);
      std::fprintf(stderr, "updates %s: %zu, median %.1f ms (camera %.1f, build %.1f)\n",
                   name.c_str(), stats.asa_ms.size(), median(stats.asa_ms), median(stats.camera_ms),
                   median(stats.build_ms));
    }
    if (!orbit_wanted) continue;
    orbits.emplace_back(name, orbit(imported->mesh, 1280, 720, g_orbit_steps));
    std::fprintf(stderr, "orbit %s: median %.1f ms (%.1f CPU), cull %.1f ms (%.1f CPU)\n",
                 name.c_str(), median(orbits.back().second.ms), median(orbits.back().second.cpu_ms),
                 median(orbits.back().second.cull_ms), median(orbits.back().second.cull_cpu_ms));
  }

  std::ostringstream md;
  md << "## View-dependent ASA (bench/view_asa_bench.cpp)\n\n"
     << "ASA with the client's defaults (1 level, t = 0.85, pixel tolerance 2) with and without "
        "a camera, at the same camera: the snapshot camera (the viewer's framing) fitted on the "
        "decoded mesh. Pictures are off-screen snapshots (OSMesa, the viewer's renderer); PSNR "
        "over RGB. Times are wall clock on a shared machine (2 cores, 8 jobs).\n\n";
  double worst_psnr = 1e9;
  for (const auto& r : pictures) worst_psnr = std::min(worst_psnr, r.psnr);
  md << "### The picture (1024 x 768, early = 10 %, middle = 50 % of the records)\n\n"
     << "| mesh | prefix | decoded faces | whole-mesh ASA faces | view-dependent faces | ratio | "
        "whole ms | view ms | PSNR dB | drawn faces (culled) | culled vs unculled dB | decoded vs "
        "whole-mesh ASA dB |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& r : pictures)
    md << "| " << r.mesh << " | " << r.prefix << " | " << r.faces << " | " << r.vi_faces << " | "
       << r.vd_faces << " | " << fmt("%.2f", double(r.vd_faces) / std::max(1u, r.vi_faces)) << " | "
       << fmt("%.1f", r.vi_ms) << " | " << fmt("%.1f", r.vd_ms) << " | " << fmt("%.1f", r.psnr)
       << " | " << r.drawn_faces << " | " << fmt("%.1f", r.cull_psnr) << " | "
       << fmt("%.1f", r.decoded_psnr) << " |\n";
  md << "\nTarget PSNR >= 38 dB everywhere: "
     << (pictures.empty()   ? "not measured"
         : worst_psnr >= 38 ? "**met**"
                            : "**not met**")
     << " (lowest " << fmt("%.1f", worst_psnr) << " dB over " << pictures.size()
     << " pictures).\n\n";

  md << "### Display faces against model size (1280 x 720, full stream)\n\n"
     << "| mesh | faces | whole-mesh ASA | view-dependent | view / whole | added by view-dependent "
        "| drawn (culled) | drawn / whole | cull ms |\n|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& r : faces_rows)
    md << "| " << r.mesh << " | " << r.faces << " | " << r.vi_faces << " | " << r.vd_faces << " | "
       << fmt("%.3f", double(r.vd_faces) / std::max(1u, r.vi_faces)) << " | "
       << (int64_t(r.vd_faces) - int64_t(r.faces)) << " | " << r.drawn_faces << " | "
       << fmt("%.3f", double(r.drawn_faces) / std::max(1u, r.vi_faces)) << " | "
       << fmt("%.1f", r.cull_ms) << " |\n";
  md << "\nTarget <= 0.25 x the whole-mesh count on the biggest model: ";
  if (!big.empty() && !faces_rows.empty()) {
    const auto& r = faces_rows.back();
    const double ratio = double(r.drawn_faces) / std::max(1u, r.vi_faces);
    md << (ratio <= 0.25 ? "**met**" : "**not met**") << " (" << r.mesh << ": "
       << fmt("%.3f", ratio) << ", faces handed to the renderer after the cull).\n\n";
  } else {
    md << "not measured (no --big model in this run).\n\n";
  }

  md << "### ASA per update as the client runs it (DisplayBuilder, one update per record, "
        "decoded meshes up to 1M faces)\n\n"
     << "| mesh | updates | largest decoded faces | view-dependent median ms (incl. camera fit) | "
        "max ms | view-dependent median CPU ms | whole-mesh median ms | whole-mesh median CPU ms "
        "|\n|---|---|---|---|---|---|---|---|\n";
  double worst_median = 0;
  for (const auto& [name, s] : updates) {
    const double m = median(s.asa_ms);
    worst_median = std::max(worst_median, m);
    md << "| " << name << " | " << s.asa_ms.size() << " | " << s.largest_faces << " | "
       << fmt("%.2f", m) << " | "
       << fmt("%.1f", s.asa_ms.empty() ? 0 : *std::max_element(s.asa_ms.begin(), s.asa_ms.end()))
       << " | " << fmt("%.2f", median(s.asa_cpu_ms)) << " | " << fmt("%.2f", median(s.vi_asa_ms))
       << " | " << fmt("%.2f", median(s.vi_asa_cpu_ms)) << " |\n";
  }
  md << "\nTarget median <= 16 ms: "
     << (updates.empty()      ? "not measured"
         : worst_median <= 16 ? "**met**"
                              : "**not met**")
     << " (highest median " << fmt("%.2f", worst_median) << " ms).\n\n";

  md << "### The parts of an update (view-dependent; real meshes up to 1M faces, and the big "
        "models' updates above half their faces)\n\n"
     << "| mesh | updates | median ms | camera fit + facing sign median ms | builder (ASA, "
        "splice, display copy) median ms | median CPU ms |\n|---|---|---|---|---|---|\n";
  for (const auto* list : {&updates, &big_updates})
    for (const auto& [name, s] : *list)
      md << "| " << name << " | " << s.asa_ms.size() << " | " << fmt("%.2f", median(s.asa_ms))
         << " | " << fmt("%.2f", median(s.camera_ms)) << " | " << fmt("%.2f", median(s.build_ms))
         << " | " << fmt("%.2f", median(s.asa_cpu_ms)) << " |\n";
  md << "\n";

  md << "### Camera orbit on a big decoded mesh (in-process, the client's DisplayBuilder with a "
        "new camera per step as the viewer drives it, display mesh included, 2 degrees a step, "
        "1280 x 720)\n\n";
  if (orbits.empty()) {
    md << "Not measured (no --big model in this run).\n\n";
  } else {
    md << "| mesh | steps | median ms | max ms | median CPU ms | median faces redone | cull median "
          "ms / CPU ms | drawn faces median |\n|---|---|---|---|---|---|---|---|\n";
    for (const auto& [name, o] : orbits) {
      std::vector<double> region(o.region_faces.begin(), o.region_faces.end());
      std::vector<double> drawn(o.drawn_faces.begin(), o.drawn_faces.end());
      md << "| " << name << " | " << o.ms.size() << " | " << fmt("%.1f", median(o.ms)) << " | "
         << fmt("%.1f", o.ms.empty() ? 0 : *std::max_element(o.ms.begin(), o.ms.end())) << " | "
         << fmt("%.1f", median(o.cpu_ms)) << " | " << fmt("%.0f", median(region)) << " | "
         << fmt("%.1f", median(o.cull_ms)) << " / " << fmt("%.1f", median(o.cull_cpu_ms)) << " | "
         << fmt("%.0f", median(drawn)) << " |\n";
    }
    md << "\n";
  }
  fs::create_directories(report_dir);
  std::ofstream(report_dir + "/view_asa.md") << md.str();
  std::printf("%s", md.str().c_str());
  return 0;
}
