// Writes the seed corpora of the fuzz targets from real streams and frames:
// procedural meshes encoded with encode_hcs, sample client/server messages
// framed with encode_frame, small mesh files (procedural ones written with
// our exporters plus the small files of the shared test meshes). Seeds are
// kept small so the committed corpus stays well under 2 MB.
//
//   fuzz_corpus_gen OUT_DIR [SHARED_MESHES_DIR]
//
// Targets that take split points from the back of their input
// (FuzzedDataProvider) get a short trailer appended, so the stream itself
// arrives whole in the seed.
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "common/codec/container.h"
#include "common/codec/encoder.h"
#include "common/codec/record_index_coder.h"
#include "common/mesh/export.h"
#include "common/mesh/procedural.h"
#include "common/mesh/textured_sphere.h"
#include "proto/framing.h"

namespace fs = std::filesystem;
using namespace meshstream;
namespace v1 = ::meshstream::v1;

namespace {

void write(const fs::path& path, const std::vector<uint8_t>& bytes) {
  fs::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

std::vector<uint8_t> read(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

// Split sizes for FuzzedDataProvider (read from the back): a few mid-size
// pieces, then the rest.
std::vector<uint8_t> with_trailer(std::vector<uint8_t> bytes, uint8_t fill) {
  for (int i = 0; i < 16; ++i) bytes.push_back(static_cast<uint8_t>(fill + 37 * i));
  return bytes;
}

void append(std::vector<uint8_t>& out, const google::protobuf::MessageLite& m) {
  proto::append_frame(m, out);
}

std::vector<uint8_t> binary_stl(const Mesh& mesh) {
  std::vector<uint8_t> out(80, 0);
  auto u32 = [&](uint32_t v) {
    for (int i = 0; i < 4; ++i) out.push_back(static_cast<uint8_t>(v >> (8 * i)));
  };
  auto f32 = [&](float f) {
    uint32_t v;
    std::memcpy(&v, &f, 4);
    u32(v);
  };
  u32(static_cast<uint32_t>(mesh.triangles.size()));
  for (const Triangle& t : mesh.triangles) {
    for (int i = 0; i < 3; ++i) f32(0);
    for (uint32_t v : t) {
      f32(mesh.positions[v].x);
      f32(mesh.positions[v].y);
      f32(mesh.positions[v].z);
    }
    out.push_back(0);
    out.push_back(0);
  }
  return out;
}

std::vector<uint8_t> ascii_stl(const Mesh& mesh) {
  std::string s = "solid seed\n";
  for (const Triangle& t : mesh.triangles) {
    s += " facet normal 0 0 0\n  outer loop\n";
    for (uint32_t v : t) {
      s += "   vertex " + std::to_string(mesh.positions[v].x) + " " +
           std::to_string(mesh.positions[v].y) + " " + std::to_string(mesh.positions[v].z) + "\n";
    }
    s += "  endloop\n endfacet\n";
  }
  s += "endsolid seed\n";
  return std::vector<uint8_t>(s.begin(), s.end());
}

std::vector<uint8_t> prefixed(uint8_t selector, const std::vector<uint8_t>& file) {
  std::vector<uint8_t> out{selector};
  out.insert(out.end(), file.begin(), file.end());
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: fuzz_corpus_gen OUT_DIR [SHARED_MESHES_DIR]\n";
    return 2;
  }
  const fs::path out = argv[1];
  struct Named {
    std::string name;
    Mesh mesh;
  };
  std::vector<Named> meshes = {
      {"icosahedron", make_icosahedron()},      {"icosphere2", make_icosphere(2)},
      {"icosphere3", make_icosphere(3)},        {"grid8", make_open_grid(8)},
      {"components3", make_multi_component(3)}, {"torus", make_torus(16, 8)},
  };
  // Attribute records (attribute_codec.h): per-vertex colours and normals;
  // per-corner texture coordinates with seams (each face its own island, so
  // every edge is a seam), face materials and an extra attribute.
  {
    Mesh colored = make_icosphere(3);
    for (const Vec3f& p : colored.positions) {
      colored.colors.push_back({0.5f + p.x / 2, 0.5f + p.y / 2, 0.5f + p.z / 2, 1.0f});
      colored.normals.push_back(p);
    }
    meshes.push_back({"icosphere3_colors", colored});
    Mesh seamed = make_torus(16, 8);
    for (uint32_t f = 0; f < seamed.face_count(); ++f) {
      for (int k = 0; k < 3; ++k) {
        seamed.corner_texcoords.corners.push_back(uint32_t(seamed.corner_texcoords.values.size()));
        seamed.corner_texcoords.values.push_back(
            {float(f % 16) / 16 + 0.01f * k, float(f / 16) / 16});
      }
      seamed.face_materials.push_back(f % 2);
    }
    seamed.materials.resize(2);
    seamed.materials[1].name = "second";
    ExtraAttribute extra;
    extra.name = "TEXCOORD_1";
    extra.components = 2;
    extra.bytes.assign(3 * seamed.face_count() * 8, 0x3f);
    seamed.extra_attributes.push_back(extra);
    meshes.push_back({"torus_seams", seamed});
  }

  // ---- hcs_decoder: whole streams, several coders and sizes.
  std::vector<uint8_t> sample_stream;
  for (const Named& m : meshes) {
    for (bool draco : {true, false}) {
      EncodeOptions options;
      options.allow_draco_base = draco;
      options.target_base_vertices = 24;
      options.record_bytes = 256;
      auto stream = encode_hcs(m.mesh, options);
      if (!stream) {
        std::cerr << m.name << ": " << stream.error().message << "\n";
        return 1;
      }
      if (m.name == "icosphere2" && draco) sample_stream = *stream;
      write(out / "hcs_decoder" / (m.name + (draco ? "_draco" : "_own") + ".hcs"),
            with_trailer(*stream, 3));
      // The same with the target's "fix checksums" flag (last byte odd).
      std::vector<uint8_t> fixing = with_trailer(*stream, 3);
      fixing.push_back(1);
      write(out / "hcs_decoder" / (m.name + (draco ? "_draco" : "_own") + "_fixcrc.hcs"), fixing);
    }
  }
  // Texture records (texture_record.h): a small textured sphere, so the
  // fuzzer starts from streams with a preview and an original image.
  {
    EncodeOptions options;
    options.target_base_vertices = 24;
    options.record_bytes = 256;
    options.plane_calibration = 1.0;
    auto stream = encode_hcs(make_textured_uv_sphere(6, 10, 24), options);
    if (!stream) {
      std::cerr << "textured sphere: " << stream.error().message << "\n";
      return 1;
    }
    write(out / "hcs_decoder" / "textured_sphere.hcs", with_trailer(*stream, 3));
    std::vector<uint8_t> fixing = with_trailer(*stream, 3);
    fixing.push_back(1);
    write(out / "hcs_decoder" / "textured_sphere_fixcrc.hcs", fixing);
  }
  auto index = read_stream_index(sample_stream);
  if (!index) {
    std::cerr << "sample stream: " << index.error().message << "\n";
    return 1;
  }

  // ---- server_frames: a client's session transcripts.
  {
    v1::ClientMessage hello;
    hello.mutable_hello()->set_protocol_version(proto::kProtocolVersion);
    hello.mutable_hello()->set_client_name("fuzz-seed");
    v1::ClientMessage list;
    list.mutable_list_models();
    v1::ClientMessage cancel;
    cancel.mutable_cancel();
    std::vector<v1::ClientMessage> streams;
    for (int kind = 0; kind < 4; ++kind) {
      v1::ClientMessage m;
      v1::StreamRequest& r = *m.mutable_stream();
      r.set_model("demo");
      r.set_resume_offset(kind == 3 ? index->records[1].offset + 5 : 0);
      if (kind == 1) r.mutable_budget()->set_bytes(index->total_bytes() / 2);
      if (kind == 2) r.mutable_budget()->set_vertices(index->records.back().vertices / 3);
      if (kind == 3) r.mutable_budget()->set_percent(40.0);
      r.set_max_chunk_bytes(kind == 0 ? 0 : 1024u << kind);
      streams.push_back(m);
    }
    // Ranged requests (StreamRequest.records): a good one, last records
    // first, and one whose ranges share a record.
    const auto last = static_cast<uint32_t>(index->records.size());
    for (int kind = 0; kind < 2; ++kind) {
      v1::ClientMessage m;
      v1::StreamRequest& r = *m.mutable_stream();
      r.set_model("demo");
      r.set_max_chunk_bytes(1024);
      auto add = [&](uint32_t first, uint32_t end) {
        v1::RecordRange* range = r.mutable_records()->add_ranges();
        range->set_first(first);
        range->set_end(end);
      };
      add(last / 2, last);
      add(1, kind == 0 ? last / 2 : last / 2 + 1);
      add(0, 1);
      streams.push_back(m);
    }
    for (size_t i = 0; i < streams.size(); ++i) {
      std::vector<uint8_t> t;
      append(t, hello);
      if (i == 0) append(t, list);
      append(t, streams[i]);
      if (i == 2) append(t, cancel);
      write(out / "server_frames" / ("session" + std::to_string(i)), with_trailer(t, 0x80));
    }
    std::vector<uint8_t> one;
    append(one, hello);
    write(out / "server_frames" / "hello_only", with_trailer(one, 1));
  }

  // ---- client_frames: a server's replies carrying a real stream.
  {
    v1::ServerMessage hello;
    hello.mutable_hello()->set_protocol_version(proto::kProtocolVersion);
    hello.mutable_hello()->set_server_name("fuzz-seed");
    v1::ServerMessage header;
    v1::StreamHeader& h = *header.mutable_header();
    h.set_model("demo");
    h.set_total_bytes(index->total_bytes());
    h.set_start_offset(0);
    for (const RecordEntry& r : index->records) {
      h.mutable_records()->add_sizes(r.size);
      h.mutable_records()->add_vertices(r.vertices);
      h.mutable_records()->add_faces(r.faces);
      h.mutable_records()->add_crc32(r.crc32);
    }
    for (size_t pieces : {1u, 3u, 7u}) {
      std::vector<uint8_t> t;
      append(t, hello);
      append(t, header);
      const size_t step = (sample_stream.size() + pieces - 1) / pieces;
      for (size_t at = 0; at < sample_stream.size(); at += step) {
        v1::ServerMessage chunk;
        const size_t n = std::min(step, sample_stream.size() - at);
        chunk.mutable_chunk()->set_offset(at);
        chunk.mutable_chunk()->set_data(sample_stream.data() + at, n);
        append(t, chunk);
      }
      v1::ServerMessage end;
      end.mutable_end()->set_reason(v1::StreamEnd::COMPLETE);
      append(t, end);
      write(out / "client_frames" / ("stream_" + std::to_string(pieces)), with_trailer(t, 0x40));
    }
    // The compact record index (StreamRequest.compact_index) the client
    // asks for: the same stream behind a header with RecordIndex.coded.
    {
      v1::ServerMessage compact = header;
      v1::RecordIndex& records = *compact.mutable_header()->mutable_records();
      records.Clear();
      auto coded = encode_record_index(index->records);
      if (coded) {
        records.set_coded(coded->data(), coded->size());
        records.set_count(static_cast<uint32_t>(index->records.size()));
        v1::StreamHeader& ch = *compact.mutable_header();
        ch.set_payload_offset(index->payload_offset);
        ch.set_end_offset(index->total_bytes());
        ch.set_end_record(static_cast<uint32_t>(index->records.size()));
        ch.set_vertices(index->records.back().vertices);
        ch.set_faces(index->records.back().faces);
        std::vector<uint8_t> t;
        append(t, hello);
        append(t, compact);
        v1::ServerMessage chunk;
        chunk.mutable_chunk()->set_offset(0);
        chunk.mutable_chunk()->set_data(sample_stream.data(), sample_stream.size());
        append(t, chunk);
        write(out / "client_frames" / "stream_compact_index", with_trailer(t, 0x40));
      }
    }
    v1::ServerMessage error;
    error.mutable_error()->set_code(v1::Error::UNKNOWN_MODEL);
    error.mutable_error()->set_message("unknown model 'x'");
    std::vector<uint8_t> t;
    append(t, hello);
    append(t, error);
    write(out / "client_frames" / "error", with_trailer(t, 9));
  }

  // ---- mesh_import: first byte = extension (0 obj, 1 ply, 2 off, 3 stl).
  {
    const fs::path tmp = fs::temp_directory_path() / "meshstream-corpus-gen";
    fs::create_directories(tmp);
    for (const Named& m : {meshes[0], meshes[3], meshes[4]}) {
      if (write_ply(m.mesh, (tmp / "a.ply").string(), PlyEncoding::kAscii) &&
          write_ply(m.mesh, (tmp / "b.ply").string(), PlyEncoding::kBinary) &&
          write_obj(m.mesh, (tmp / "c.obj").string())) {
        write(out / "mesh_import" / (m.name + "_ascii.ply"), prefixed(1, read(tmp / "a.ply")));
        write(out / "mesh_import" / (m.name + "_binary.ply"), prefixed(1, read(tmp / "b.ply")));
        write(out / "mesh_import" / (m.name + ".obj"), prefixed(0, read(tmp / "c.obj")));
      }
      write(out / "mesh_import" / (m.name + "_binary.stl"), prefixed(3, binary_stl(m.mesh)));
      write(out / "mesh_import" / (m.name + "_ascii.stl"), prefixed(3, ascii_stl(m.mesh)));
    }
    fs::remove_all(tmp);
    if (argc > 2) {
      for (const auto& entry : fs::directory_iterator(argv[2])) {
        const std::string ext = entry.path().extension().string();
        if (entry.file_size() > 16 * 1024) continue;
        const uint8_t selector = ext == ".obj"   ? 0
                                 : ext == ".ply" ? 1
                                 : ext == ".off" ? 2
                                 : ext == ".stl" ? 3
                                                 : 255;
        if (selector == 255) continue;
        write(out / "mesh_import" / entry.path().filename(),
              prefixed(selector, read(entry.path())));
      }
    }
  }
  std::cout << "corpus written to " << out.string() << "\n";
  return 0;
}
