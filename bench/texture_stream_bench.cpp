// Texture records (texture_stream.h): what the preview costs the first
// display. For every mesh given and every image given, the stream's first
// display without textures (header, index, base record) and with the
// image's preview (the first display is then textured), and where the
// image's larger levels land. Usage:
//   texture_stream_bench --images a.png b.jpg ... --meshes m1.ply m2.off ...
// (no meshes: a procedural UV sphere).
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "common/codec/container.h"
#include "common/codec/encoder.h"
#include "common/codec/texture_record.h"
#include "common/codec/texture_stream.h"
#include "common/mesh/import.h"
#include "common/mesh/textured_sphere.h"

using namespace meshstream;

int main(int argc, char** argv) {
  std::vector<std::string> images, meshes;
  std::vector<std::string>* into = nullptr;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--images") == 0)
      into = &images;
    else if (std::strcmp(argv[i], "--meshes") == 0)
      into = &meshes;
    else if (into)
      into->push_back(argv[i]);
  }
  std::vector<std::pair<std::string, Mesh>> inputs;
  for (const std::string& path : meshes) {
    auto imported = import_mesh(path);
    if (!imported) {
      std::fprintf(stderr, "%s: %s\n", path.c_str(), imported.error().message.c_str());
      continue;
    }
    inputs.emplace_back(path.substr(path.find_last_of('/') + 1), std::move(imported->mesh));
  }
  if (inputs.empty()) {
    Mesh sphere = make_textured_uv_sphere(24, 48, 16);
    sphere.textures.clear();
    sphere.materials.clear();
    sphere.face_materials.clear();
    inputs.emplace_back("uv_sphere_24x48", std::move(sphere));
  }
  std::printf(
      "| mesh | image | image bytes | first display | with preview | ratio | preview px | "
      "middle at | original at | stream | with textures "
      "|\n|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (auto& [name, mesh] : inputs) {
    auto stream = encode_hcs(mesh, EncodeOptions{});
    if (!stream) {
      std::fprintf(stderr, "%s: %s\n", name.c_str(), stream.error().message.c_str());
      continue;
    }
    auto plain = read_stream_index(*stream);
    const uint64_t first = plain->payload_offset + plain->records[0].size;
    for (const std::string& image : images) {
      std::ifstream in(image, std::ios::binary);
      Texture t;
      t.name = image.substr(image.find_last_of('/') + 1);
      t.bytes.assign(std::istreambuf_iterator<char>(in), {});
      auto textured = add_texture_records(*stream, {t});
      if (!textured) {
        std::fprintf(stderr, "%s: %s\n", image.c_str(), textured.error().message.c_str());
        continue;
      }
      auto index = read_stream_index(*textured);
      const RecordEntry& preview = index->records[1];
      const uint64_t with = preview.offset + preview.size;
      auto level = read_texture_record(
          record_payload(preview, {textured->data() + preview.offset, preview.size}));
      std::string middle = "-", original = "-";
      for (const RecordEntry& r : index->records) {
        if ((*textured)[r.offset] != kRecordTexture || r.offset == preview.offset) continue;
        auto l = read_texture_record(record_payload(r, {textured->data() + r.offset, r.size}));
        char at[64];
        std::snprintf(at, sizeof at, "%.0f %%",
                      100.0 * double(r.offset) / double(textured->size()));
        (l->original ? original : middle) = at;
      }
      std::printf("| %s | %s | %zu | %llu | %llu | %.3f | %ux%u | %s | %s | %zu | %zu |\n",
                  name.c_str(), t.name.c_str(), t.bytes.size(), (unsigned long long)first,
                  (unsigned long long)with, double(with) / double(first), level->width,
                  level->height, middle.c_str(), original.c_str(), stream->size(),
                  textured->size());
    }
  }
  return 0;
}
