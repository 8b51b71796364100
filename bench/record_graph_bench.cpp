// How local the stream's records are, and what a close-up view would have
// to fetch (issue 17, view-dependent streaming; docs/view-dependent-records.md).
//
// Per real mesh: the record table (record_table.h) of the default stream
// (ASA guidance off: it is header bytes only), the records' bounding-sphere
// radii against the model's, and for views that each see a tenth of the
// surface (a ball around a random surface point holding 10 % of the area;
// 8 views a mesh, fixed seed) the share of the stream's bytes a client
// would fetch, header and index included:
//   - records: the records whose sphere meets the view, closed under needs
//     (today's records, were they addressable);
//   - elements: the same at the finest grain the stream has (one inserted
//     vertex, one vertex's plane step), closed under the element needs:
//     the bound any grouping of today's layers can reach;
//   - cells: the elements regrouped into records by (layer, cell) for
//     structure and (layer of the vertex, plane step, cell) for planes,
//     with the cells the encoder's option draws for cells of about n
//     vertices (locality_cells.h: one grid a level of layers), their bytes
//     the elements' shares: what records local by construction would
//     fetch (an estimate: the coding of regrouped records is not measured).
// Also the mean number of needs a record. The same for the stream encoded
// with `EncodeOptions::locality_cell_vertices = n` (cell borders locked,
// locality_cells.h), with its size and its
// rate-distortion against the default: the geometric mean, over 7
// log-spaced budgets from 1/64 to 1/2 of the default stream's size, of the
// RMS ratio at equal bytes (rd_measure.h).
//
//   record_graph_bench [--meshes a,b] [--cell-vertices 32,512] [--unlocked-share S] [--views 8]
//   [--out FILE]
//
// --unlocked-share S: cells only in the layers that start with more than S
// of the vertices (EncodeOptions::locality_unlocked_share; default 0).
// The meshes are found in $MESHSTREAM_TEST_MESHES (else ../shared/meshes);
// bench/REPORT.md ran 32,128 and 512,2048 on the 13 real meshes and
// 512,2048 on /work/big's dragon_x1.ply.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "bench/real_mesh_list.h"
#include "common/codec/container.h"
#include "common/codec/encoder.h"
#include "common/codec/locality_cells.h"
#include "common/codec/quantize.h"
#include "common/codec/rd_measure.h"
#include "common/codec/record_table.h"
#include "common/mesh/import.h"

namespace {

using namespace meshstream;

std::string mesh_dir() {
  if (const char* env = std::getenv("MESHSTREAM_TEST_MESHES"); env && *env) return env;
  return (std::filesystem::path(__FILE__).parent_path().parent_path() / ".." / "shared" / "meshes")
      .string();
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(q * double(v.size())))];
}

struct View {
  Vec3d center;
  double radius = 0;
};

// Balls around random surface points (by area), each holding `share` of
// the surface area (by face centroid).
std::vector<View> views_of(const std::vector<Vec3f>& pos, const std::vector<Triangle>& faces,
                           int count, double share) {
  std::vector<double> area(faces.size());
  std::vector<Vec3d> centroid(faces.size());
  double total = 0;
  for (size_t f = 0; f < faces.size(); ++f) {
    const Vec3d a = to_double(pos[faces[f][0]]), b = to_double(pos[faces[f][1]]),
                c = to_double(pos[faces[f][2]]);
    area[f] = 0.5 * length(cross(b - a, c - a));
    centroid[f] = (a + b + c) * (1.0 / 3);
    total += area[f];
  }
  std::mt19937_64 rng(17);
  std::discrete_distribution<size_t> pick(area.begin(), area.end());
  std::vector<View> out;
  std::vector<std::pair<double, size_t>> by_distance(faces.size());
  for (int i = 0; i < count; ++i) {
    View v;
    v.center = centroid[pick(rng)];
    for (size_t f = 0; f < faces.size(); ++f)
      by_distance[f] = {squared_length(centroid[f] - v.center), f};
    std::sort(by_distance.begin(), by_distance.end());
    double sum = 0;
    for (const auto& [d2, f] : by_distance) {
      sum += area[f];
      v.radius = std::sqrt(d2);
      if (sum >= share * total) break;
    }
    out.push_back(v);
  }
  return out;
}

bool meets(const View& v, const BoundingSphere& s) {
  return length(to_double(s.center) - v.center) <= v.radius + s.radius;
}

// Closure over a graph given as CSR needs; returns the bytes of the set.
double closed_bytes(const std::vector<double>& bytes, const std::vector<uint32_t>& begin,
                    const std::vector<uint32_t>& needs, std::vector<uint32_t> seeds) {
  std::vector<uint8_t> in(bytes.size(), 0);
  double sum = 0;
  std::vector<uint32_t> stack;
  for (uint32_t s : seeds)
    if (!in[s]) in[s] = 1, stack.push_back(s);
  while (!stack.empty()) {
    const uint32_t x = stack.back();
    stack.pop_back();
    sum += bytes[x];
    for (uint32_t i = begin[x]; i < begin[x + 1]; ++i)
      if (!in[needs[i]]) in[needs[i]] = 1, stack.push_back(needs[i]);
  }
  return sum;
}

struct Locality {
  size_t records = 0, groups = 0;
  double needs_per_record = 0;
  double structure_radius_median = 0, structure_radius_p90 = 0, plane_radius_median = 0;
  double visible = 0, closed = 0, elements = 0, cells = 0;  // medians over views, shares
  double closed_max = 0, cells_max = 0, cells_visible = 0;
};

Locality locality_of(const std::vector<uint8_t>& stream, uint32_t cell_vertices,
                     double unlocked_share, int view_count) {
  Locality out;
  RecordTrace trace;
  auto table = build_record_table(stream, &trace);
  if (!table) {
    std::fprintf(stderr, "record table: %s\n", table.error().message.c_str());
    std::exit(1);
  }
  auto index = read_stream_index(stream);
  const StreamHeader& header = index->header;
  const double total = double(table->total_bytes), prefix = double(table->prefix_bytes);
  const double model = table->model.radius;
  out.records = table->records.size();
  std::vector<double> sr, pr;
  uint32_t layers_seen = 0;
  for (const RecordTableEntry& e : table->records) {
    out.needs_per_record += double(e.needs.size()) / double(table->records.size());
    if (e.kind == RecordKind::kStructure) sr.push_back(e.sphere.radius / model);
    if (e.kind == RecordKind::kPlane) pr.push_back(e.sphere.radius / model);
    layers_seen = std::max(layers_seen, e.layer);
  }
  if (layers_seen != header.layer_count)
    std::fprintf(stderr, "note: %u layers started, the header says %u\n", layers_seen,
                 header.layer_count);
  out.structure_radius_median = quantile(sr, 0.5);
  out.structure_radius_p90 = quantile(sr, 0.9);
  out.plane_radius_median = quantile(pr, 0.5);

  // Records as a CSR graph.
  const uint32_t nr = static_cast<uint32_t>(table->records.size());
  std::vector<double> rbytes(nr);
  std::vector<uint32_t> rbegin(nr + 1, 0), rneeds;
  for (uint32_t r = 0; r < nr; ++r) {
    rbytes[r] = double(table->records[r].bytes);
    rneeds.insert(rneeds.end(), table->records[r].needs.begin(), table->records[r].needs.end());
    rbegin[r + 1] = static_cast<uint32_t>(rneeds.size());
  }
  // Elements.
  const uint32_t ne = static_cast<uint32_t>(trace.elements.size());
  std::vector<double> ebytes(ne);
  std::vector<uint32_t> ebegin(ne + 1, 0);
  for (uint32_t i = 0; i < ne; ++i) {
    ebytes[i] = trace.elements[i].bytes;
    ebegin[i] = trace.elements[i].needs_begin;
    ebegin[i + 1] = trace.elements[i].needs_end;
  }
  // Cells: group elements by key.
  QuantGrid grid;
  grid.bounds = header.bounds;
  grid.bits = header.quant_bits;
  std::vector<uint32_t> vertex_layer(trace.positions.size(), 0),
      plane_steps(trace.positions.size(), 0);
  // The cells of each restored layer L as the encoder drew them: decimation
  // layer layer_count - L, which started with the vertices there are once
  // L is restored.
  std::vector<uint32_t> layer_vertices(header.layer_count + 1, header.base_vertex_count);
  for (uint32_t r = 0; r < nr; ++r) {
    const RecordTableEntry& e = table->records[r];
    if (e.kind == RecordKind::kStructure && e.layer <= header.layer_count)
      layer_vertices[e.layer] = std::max(layer_vertices[e.layer], index->records[r].vertices);
  }
  // The grids as the encoder's CellLevels drew them, finest layer first.
  std::vector<uint32_t> layer_cells(header.layer_count + 1, 1);
  {
    CellLevels levels(cell_vertices, unlocked_for_share(header.vertex_count, unlocked_share));
    for (uint32_t L = header.layer_count; L >= 1; --L)
      layer_cells[L] = levels.next(layer_vertices[L]);
  }
  auto cell_in_layer = [&](const Vec3i& q, uint32_t layer) -> uint32_t {
    const uint32_t n = layer_cells[std::min(layer, header.layer_count)];
    if (n < 2) return 0;
    return locality_cell(q, n, grid.bits);
  };
  std::map<std::tuple<int, uint32_t, uint32_t, uint32_t>, uint32_t> key_to_group;
  std::vector<uint32_t> group_of(ne);
  std::vector<std::vector<Vec3f>> group_points;
  std::vector<double> gbytes;
  for (uint32_t i = 0; i < ne; ++i) {
    const RecordElement& el = trace.elements[i];
    const RecordTableEntry& rec = table->records[el.record];
    std::tuple<int, uint32_t, uint32_t, uint32_t> key{0, 0, 0, 0};
    const Vec3i q = grid.quantize(trace.positions[el.vertex]);
    if (rec.kind == RecordKind::kStructure) {
      vertex_layer[el.vertex] = rec.layer;
      key = {1, rec.layer, 0, cell_in_layer(q, rec.layer)};
    } else if (rec.kind == RecordKind::kPlane) {
      key = {2, vertex_layer[el.vertex], plane_steps[el.vertex]++,
             cell_in_layer(q, vertex_layer[el.vertex])};
    }
    auto [at, fresh] = key_to_group.try_emplace(key, static_cast<uint32_t>(gbytes.size()));
    if (fresh) gbytes.push_back(0), group_points.emplace_back();
    group_of[i] = at->second;
    gbytes[at->second] += el.bytes;
    if (rec.kind != RecordKind::kBase)
      group_points[at->second].push_back(trace.positions[el.vertex]);
  }
  const uint32_t ng = static_cast<uint32_t>(gbytes.size());
  out.groups = ng;
  std::vector<std::vector<uint32_t>> gneeds(ng);
  for (uint32_t i = 0; i < ne; ++i)
    for (uint32_t k = trace.elements[i].needs_begin; k < trace.elements[i].needs_end; ++k) {
      const uint32_t g = group_of[trace.element_needs[k]];
      if (g != group_of[i]) gneeds[group_of[i]].push_back(g);
    }
  std::vector<uint32_t> gbegin(ng + 1, 0), gflat;
  for (uint32_t g = 0; g < ng; ++g) {
    std::sort(gneeds[g].begin(), gneeds[g].end());
    gneeds[g].erase(std::unique(gneeds[g].begin(), gneeds[g].end()), gneeds[g].end());
    gflat.insert(gflat.end(), gneeds[g].begin(), gneeds[g].end());
    gbegin[g + 1] = static_cast<uint32_t>(gflat.size());
  }
  std::vector<BoundingSphere> gsphere(ng);
  for (uint32_t g = 0; g < ng; ++g) gsphere[g] = bounding_sphere(group_points[g]);
  const uint32_t base_group = group_of[0];

  std::vector<double> visible, closed, elements, cells, cells_visible;
  for (const View& v : views_of(trace.positions, trace.faces, view_count, 0.1)) {
    std::vector<uint32_t> seeds{0};
    double seen = 0;
    for (uint32_t r = 0; r < nr; ++r)
      if (meets(v, table->records[r].sphere)) seeds.push_back(r), seen += rbytes[r];
    visible.push_back((prefix + seen) / total);
    closed.push_back((prefix + closed_bytes(rbytes, rbegin, rneeds, seeds)) / total);
    std::vector<uint32_t> eseeds{0};
    for (uint32_t i = 1; i < ne; ++i)
      if (length(to_double(trace.positions[trace.elements[i].vertex]) - v.center) <= v.radius)
        eseeds.push_back(i);
    elements.push_back((prefix + closed_bytes(ebytes, ebegin, trace.element_needs, eseeds)) /
                       total);
    std::vector<uint32_t> gseeds{base_group};
    double gseen = gbytes[base_group];
    for (uint32_t g = 0; g < ng; ++g)
      if (g != base_group && meets(v, gsphere[g])) gseeds.push_back(g), gseen += gbytes[g];
    cells_visible.push_back((prefix + gseen) / total);
    cells.push_back((prefix + closed_bytes(gbytes, gbegin, gflat, gseeds)) / total);
  }
  out.visible = quantile(visible, 0.5);
  out.closed = quantile(closed, 0.5);
  out.closed_max = quantile(closed, 1.0);
  out.elements = quantile(elements, 0.5);
  out.cells = quantile(cells, 0.5);
  out.cells_max = quantile(cells, 1.0);
  out.cells_visible = quantile(cells_visible, 0.5);
  return out;
}

double rd_score(const RdMeasure& measure, const std::vector<uint8_t>& stream, uint64_t reference) {
  auto curve = measure.curve(stream, reference);
  if (!curve) {
    std::fprintf(stderr, "rd: %s\n", curve.error().message.c_str());
    std::exit(1);
  }
  return RdMeasure::score(*curve);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> meshes = bench::kRealMeshes;
  std::vector<uint32_t> cells{32, 512};
  int view_count = 8;
  double unlocked_share = 0;
  std::string out_path;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", arg.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (arg == "--meshes") {
      meshes = bench::split_commas(value());
    } else if (arg == "--cell-vertices") {
      cells.clear();
      for (const std::string& c : bench::split_commas(value())) cells.push_back(std::stoul(c));
    } else if (arg == "--unlocked-share") {
      unlocked_share = std::stod(value());
    } else if (arg == "--views") {
      view_count = std::stoi(value());
    } else if (arg == "--out") {
      out_path = value();
    } else {
      std::fprintf(stderr,
                   "usage: record_graph_bench [--meshes a,b] [--cell-vertices 32,512] "
                   "[--unlocked-share S] [--views "
                   "8] [--out FILE]\n");
      return 2;
    }
  }
  std::ostringstream report;
  report << "| mesh | records | needs a record | struct. radius med / p90 | plane radius med | "
            "view: visible | "
            "records closed (max) | elements | cell vertices | groups | cells visible | cells "
            "closed (max) | "
            "locked: bytes | RD | records closed | elements | cells closed (max) |\n"
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const std::string& name : meshes) {
    auto imported = import_mesh(mesh_dir() + "/" + name);
    if (!imported) {
      std::fprintf(stderr, "%s: %s\n", name.c_str(), imported.error().message.c_str());
      return 1;
    }
    const Mesh& mesh = imported->mesh;
    EncodeOptions options;
    options.asa_guidance = false;
    const auto t0 = std::chrono::steady_clock::now();
    auto plain = encode_hcs(mesh, options);
    if (!plain) {
      std::fprintf(stderr, "%s: %s\n", name.c_str(), plain.error().message.c_str());
      return 1;
    }
    const double encode_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    Mesh reference;
    {
      auto q = quantized_reference(mesh, options.quant_bits);
      reference = std::move(*q);
    }
    RdMeasureOptions rd_options;
    rd_options.budgets = 7;
    rd_options.last_fraction = 0.5;
    auto measure = RdMeasure::prepare(reference, rd_options);
    const double plain_score = rd_score(*measure, *plain, plain->size());
    for (uint32_t n : cells) {
      const Locality a = locality_of(*plain, n, unlocked_share, view_count);
      options.locality_cell_vertices = n;
      options.locality_unlocked_share = unlocked_share;
      auto locked = encode_hcs(mesh, options);
      options.locality_cell_vertices = 0;
      if (!locked) {
        std::fprintf(stderr, "%s: %s\n", name.c_str(), locked.error().message.c_str());
        return 1;
      }
      const Locality b = locality_of(*locked, n, unlocked_share, view_count);
      const double rd = std::exp(rd_score(*measure, *locked, plain->size()) - plain_score);
      {
        auto ia = read_stream_index(*plain);
        auto ib = read_stream_index(*locked);
        std::fprintf(
            stderr, "%s n=%u: base %u -> %u vertices, layers %u -> %u, records %zu -> %zu\n",
            name.c_str(), n, ia->header.base_vertex_count, ib->header.base_vertex_count,
            ia->header.layer_count, ib->header.layer_count, ia->records.size(), ib->records.size());
      }
      char line[1024];
      std::snprintf(
          line, sizeof line,
          "| %s | %zu | %.1f | %.3f / %.3f | %.3f | %.3f | %.3f (%.3f) | %.3f | %u | %zu | "
          "%.3f | %.3f (%.3f) | %.4f | %.3f | %.3f | %.3f | %.3f (%.3f) |\n",
          name.c_str(), a.records, a.needs_per_record, a.structure_radius_median,
          a.structure_radius_p90, a.plane_radius_median, a.visible, a.closed, a.closed_max,
          a.elements, n, a.groups, a.cells_visible, a.cells, a.cells_max,
          double(locked->size()) / double(plain->size()), rd, b.closed, b.elements, b.cells,
          b.cells_max);
      report << line;
      std::fputs(line, stdout);
      std::fflush(stdout);
    }
    std::fprintf(stderr, "%s: %zu bytes, encoded in %.1f s\n", name.c_str(), plain->size(),
                 encode_s);
  }
  if (!out_path.empty()) std::ofstream(out_path) << report.str();
  return 0;
}
