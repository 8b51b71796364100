// `meshstream info MESH [--json]`: the facts of a mesh file — what it holds
// (attributes, materials, skipped properties, even what import does not
// keep), its topology as the file has it (welded, degenerate faces dropped,
// nothing repaired), what import changed to make it usable by the codec, and
// the topology of the result.
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "common/mesh/import.h"
#include "common/mesh/topology.h"
#include "tools/commands.h"

namespace meshstream::tools {
namespace {

nlohmann::json vec_json(const Vec3f& v) { return {v.x, v.y, v.z}; }

nlohmann::json stats_json(const MeshStats& s) {
  nlohmann::json j = {{"vertices", s.vertices},
                      {"referenced_vertices", s.referenced_vertices},
                      {"faces", s.faces},
                      {"edges", s.edges},
                      {"boundary_edges", s.boundary_edges},
                      {"boundary_loops", s.boundary_loops},
                      {"components", s.components},
                      {"euler", s.euler},
                      {"manifold", s.manifold},
                      {"nonmanifold_edges", s.nonmanifold_edges},
                      {"nonmanifold_vertices", s.nonmanifold_vertices},
                      {"orientation_conflicts", s.orientation_conflicts},
                      {"duplicate_faces", s.duplicate_faces},
                      {"bbox",
                       {{"min", vec_json(s.bbox.min)},
                        {"max", vec_json(s.bbox.max)},
                        {"diagonal", s.bbox.diagonal()}}}};
  j["genus"] = s.genus_valid ? nlohmann::json(s.genus) : nlohmann::json(nullptr);
  return j;
}

nlohmann::json report_json(const CleanReport& r) {
  return {{"vertices_in_file", r.vertices_in_file},
          {"faces_in_file", r.faces_in_file},
          {"welded_vertices", r.welded_vertices},
          {"degenerate_faces", r.degenerate_faces},
          {"duplicate_faces", r.duplicate_faces},
          {"unreferenced_vertices", r.unreferenced_vertices},
          {"nonmanifold_edges", r.nonmanifold_edges},
          {"nonmanifold_vertices", r.nonmanifold_vertices},
          {"split_vertices", r.split_vertices},
          {"detached_faces", r.detached_faces},
          {"flipped_faces", r.flipped_faces},
          {"double_sided_flaps", r.double_sided_flaps},
          {"changed", r.changed()},
          {"notes", r.notes}};
}

// The file's own attributes, materials and skipped data, whether or not
// import keeps them; the stream (encode) carries what import keeps
// (attribute records, docs/hcs-format.md).
constexpr const char* kEncodeDrops = "carried by encode";

struct AttributeRow {
  const char* name;  // text output
  const char* key;   // JSON
  const char* unit;  // what count counts
  const AttributeInFile& in_file;
  bool kept;  // the imported mesh has it
};

std::vector<AttributeRow> attribute_rows(const ImportedMesh& m, bool obj) {
  const FileContents& c = m.contents;
  return {{"normals", "normals", obj ? "'vn' lines" : "values", c.normals, !m.mesh.normals.empty()},
          {"texture coordinates", "texcoords", obj ? "'vt' lines" : "values", c.texcoords,
           !m.mesh.texcoords.empty()},
          {"colours", "colors", "vertices", c.colors, !m.mesh.colors.empty()}};
}

// "kept by import and subdivide; not carried: ..." or "not kept by import:
// why; ..." for an attribute the file has.
std::string attribute_fate(const AttributeRow& row) {
  if (row.kept) return std::string("kept by import and subdivide; ") + kEncodeDrops;
  const std::string why = row.in_file.dropped.empty() ? "not read" : row.in_file.dropped;
  return "not kept by import: " + why;
}

nlohmann::json contents_json(const ImportedMesh& m, bool obj) {
  const FileContents& c = m.contents;
  nlohmann::json j = {{"format", c.format}};
  for (const AttributeRow& row : attribute_rows(m, obj)) {
    nlohmann::json a = {{"count", row.in_file.count}, {"kept_by_import", row.kept}};
    if (row.in_file.count > 0 && !row.kept)
      a["dropped"] = row.in_file.dropped.empty() ? "not read" : row.in_file.dropped;
    a["carried_by_encode"] = row.kept;
    j[row.key] = a;
  }
  nlohmann::json libraries = nlohmann::json::array();
  for (const MaterialLibrary& l : c.material_libraries) {
    libraries.push_back({{"name", l.name},
                         {"found", l.found},
                         {"materials", l.materials},
                         {"textures", l.textures}});
  }
  j["material_libraries"] = libraries;
  j["materials_used"] = c.materials_used;
  j["extra_properties"] = c.extra_properties;
  j["other_elements"] = c.other_elements;
  return j;
}

std::string joined(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& s : items) out += (out.empty() ? "" : ", ") + s;
  return out;
}

void print_contents(const ImportedMesh& m, bool obj) {
  const FileContents& c = m.contents;
  std::printf("file holds (%s; what import does not keep too):\n", c.format.c_str());
  bool any = false;
  for (const AttributeRow& row : attribute_rows(m, obj)) {
    if (row.in_file.count == 0) continue;
    any = true;
    std::printf("  %-21s %llu %s (%s)\n", row.name,
                static_cast<unsigned long long>(row.in_file.count), row.unit,
                attribute_fate(row).c_str());
  }
  for (const MaterialLibrary& l : c.material_libraries) {
    any = true;
    if (!l.found) {
      std::printf("  %-21s %s (not found beside the file; not read)\n", "material library",
                  l.name.c_str());
      continue;
    }
    std::printf("  %-21s %s: %zu material%s (%s)%s%s; not read\n", "material library",
                l.name.c_str(), l.materials.size(), l.materials.size() == 1 ? "" : "s",
                joined(l.materials).c_str(), l.textures.empty() ? "" : ", textures ",
                joined(l.textures).c_str());
  }
  if (!c.materials_used.empty()) {
    any = true;
    std::printf("  %-21s %s (not read)\n", "materials used", joined(c.materials_used).c_str());
  }
  if (!c.extra_properties.empty()) {
    any = true;
    std::printf("  %-21s %s (not read)\n", "other properties", joined(c.extra_properties).c_str());
  }
  if (!c.other_elements.empty()) {
    any = true;
    std::printf("  %-21s %s (not read)\n", "other elements", joined(c.other_elements).c_str());
  }
  if (!any) std::printf("  positions and faces only\n");
}

std::string attributes_of(const Mesh& m) {
  std::string a;
  auto add = [&a](bool present, const char* name) {
    if (!present) return;
    if (!a.empty()) a += ", ";
    a += name;
  };
  add(!m.normals.empty(), "normals");
  add(!m.colors.empty(), "colors");
  add(!m.texcoords.empty(), "texture coordinates");
  return a.empty() ? "none" : a;
}

void print_stats(const MeshStats& s) {
  std::printf("  vertices        %u\n", s.referenced_vertices);
  std::printf("  faces           %u\n", s.faces);
  std::printf("  edges           %u\n", s.edges);
  std::printf("  boundary        %u edges in %u loops\n", s.boundary_edges, s.boundary_loops);
  std::printf("  components      %u\n", s.components);
  std::printf("  euler           %lld\n", static_cast<long long>(s.euler));
  if (s.genus_valid) {
    std::printf("  genus           %lld\n", static_cast<long long>(s.genus));
  } else {
    std::printf("  genus           - (not a consistently oriented manifold)\n");
  }
  std::printf("  manifold        %s", s.manifold ? "yes" : "no");
  if (!s.manifold) {
    std::printf(" (%u non-manifold edges, %u non-manifold vertices)", s.nonmanifold_edges,
                s.nonmanifold_vertices);
  }
  std::printf("\n");
  if (s.orientation_conflicts)
    std::printf("  orientation     %u conflicting edges\n", s.orientation_conflicts);
  if (s.duplicate_faces) std::printf("  duplicates      %u faces\n", s.duplicate_faces);
}

}  // namespace

int run_info_mesh(const std::string& path, bool json) {
  // The file as drawn (for the manifest-style facts), then as import makes it.
  ImportOptions analysis;
  analysis.keep_nonmanifold = true;
  analysis.drop_duplicate_faces = false;
  MeshStats file_stats;
  {
    // Released before the second import: never two big meshes at once.
    auto as_drawn = import_mesh(path, analysis);
    if (!as_drawn) return report_failure(as_drawn.error());
    file_stats = compute_stats(as_drawn->mesh);
  }
  auto imported = import_mesh(path);
  if (!imported) return report_failure(imported.error());
  const MeshStats stats = compute_stats(imported->mesh);
  const CleanReport& r = imported->report;
  const bool obj = imported->contents.format == "OBJ";
  for (MaterialLibrary& library : imported->contents.material_libraries)
    library = read_material_library(path, library.name);

  if (json) {
    nlohmann::json out = {{"path", path},
                          {"file", stats_json(file_stats)},
                          {"import", report_json(r)},
                          {"mesh", stats_json(stats)},
                          {"attributes",
                           {{"normals", !imported->mesh.normals.empty()},
                            {"colors", !imported->mesh.colors.empty()},
                            {"texcoords", !imported->mesh.texcoords.empty()}}},
                          {"contents", contents_json(*imported, obj)}};
    std::cout << out.dump() << "\n";
    return 0;
  }
  std::printf("%s\n", path.c_str());
  std::printf("file: %u vertices, %u triangles (after fan-triangulating polygons)\n",
              r.vertices_in_file, r.faces_in_file);
  print_contents(*imported, obj);
  std::printf("as drawn (bit-identical positions welded, degenerate faces dropped):\n");
  print_stats(file_stats);
  std::printf("import changed:%s\n", r.changed() ? "" : " nothing");
  auto line = [](uint32_t count, const char* what) {
    if (count) std::printf("  %-15s %u\n", what, count);
  };
  line(r.welded_vertices, "welded");
  line(r.degenerate_faces, "degenerate");
  line(r.duplicate_faces, "duplicates");
  line(r.unreferenced_vertices, "unreferenced");
  line(r.split_vertices, "split vertices");
  line(r.detached_faces, "detached faces");
  line(r.flipped_faces, "flipped faces");
  line(r.double_sided_flaps, "flaps dropped");
  for (const std::string& note : r.notes) std::printf("  note: %s\n", note.c_str());
  std::printf("mesh (what encode and subdivide work on):\n");
  print_stats(stats);
  const BoundingBox& box = stats.bbox;
  std::printf("  bounding box    (%.9g, %.9g, %.9g) - (%.9g, %.9g, %.9g), diagonal %.9g\n",
              box.min.x, box.min.y, box.min.z, box.max.x, box.max.y, box.max.z, box.diagonal());
  const std::string kept = attributes_of(imported->mesh);
  std::printf("  attributes      %s%s\n", kept.c_str(),
              kept == "none" ? " kept (see \"file holds\" for what the file has)"
                             : (std::string(" (") + kEncodeDrops + ")").c_str());
  return 0;
}

}  // namespace meshstream::tools
