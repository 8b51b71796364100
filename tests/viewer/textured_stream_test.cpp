// A textured model through the real meshstream-server and
// meshstream-client: the client's off-screen snapshot (--snapshot) of a
// procedural textured sphere is textured (the checker's colours, not
// grey), at the end of the stream and right after the texture's preview
// (record 1: the first display is already textured); and what the client's
// --out --out-format glb writes is the textured mesh and passes the Khronos
// glTF validator.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include "client/viewer/rgba_image.h"
#include "common/codec/container.h"
#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "common/codec/texture_record.h"
#include "common/mesh/import.h"
#include "common/mesh/textured_sphere.h"
#include "tests/gltf_validator.h"
#include "tests/test_meshes.h"
#include "tests/viewer/child_process.h"
#include "tests/viewer/image_checks.h"
#include "tests/viewer/saturated_pixels.h"

namespace meshstream::client {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

std::string binary(const char* sub) { return std::string(MESHSTREAM_BINARY_DIR) + "/" + sub; }

TEST(TexturedStream, ClientSnapshotOfATexturedSphereIsTextured) {
  const std::string server_bin = binary("server/meshstream-server");
  const std::string client_bin = binary("client/meshstream-client");
  if (!fs::exists(server_bin) || !fs::exists(client_bin))
    GTEST_SKIP() << "meshstream-server or meshstream-client not built";
  EncodeOptions options;
  options.plane_calibration = 1.0;
  auto stream = encode_hcs(make_textured_uv_sphere(32, 64, 256), options);
  ASSERT_TRUE(stream) << stream.error().message;
  auto decoded = decode_hcs(*stream);
  ASSERT_TRUE(decoded) << decoded.error().message;
  ASSERT_EQ(decoded->textures.size(), 1u) << "the texture travels in the stream";
  if (decoded->texcoords.empty() && decoded->corner_texcoords.empty()) {
    GTEST_SKIP() << "the codec does not carry texture coordinates yet (issue 18 point 2): the "
                    "texture arrives but cannot be mapped onto the surface";
  }

  const fs::path dir =
      fs::temp_directory_path() / ("meshstream_textured_e2e_" + std::to_string(::getpid()));
  fs::create_directories(dir / "models");
  {
    std::ofstream out(dir / "models" / "sphere.hcs", std::ios::binary);
    out.write(reinterpret_cast<const char*>(stream->data()), std::streamsize(stream->size()));
  }
  testing::ChildProcess server;
  ASSERT_TRUE(server.start({server_bin, "--models", (dir / "models").string(), "--cache",
                            (dir / "cache").string(), "--listen", "127.0.0.1:0"},
                           (dir / "server.log").string()));
  std::string address;
  for (int i = 0; i < 20 && address.empty(); ++i) {
    auto line = server.read_line(30s);
    if (!line) break;
    if (line->rfind("listening on ", 0) == 0) address = line->substr(13);
  }
  ASSERT_FALSE(address.empty()) << "server did not start";
  auto snapshot = [&](const std::string& name, std::vector<std::string> extra) {
    std::vector<std::string> args{
        client_bin, address,    "sphere", "--quiet",    "--no-asa",           "--width",
        "256",      "--height", "256",    "--snapshot", (dir / name).string()};
    args.insert(args.end(), extra.begin(), extra.end());
    testing::ChildProcess client;
    EXPECT_TRUE(client.start(args, (dir / "client.log").string()));
    EXPECT_EQ(client.wait(60s).value_or(-1), 0);
    auto image = read_png((dir / name).string());
    EXPECT_TRUE(image) << (image ? "" : image.error().message);
    if (!image) return RgbaImage{};
    testing::keep_for_inspection(*image, "textured_e2e_" + fs::path(name).stem().string());
    return *image;
  };
  const auto final_hues = testing::saturated_by_hue(snapshot("final.png", {}));
  // The preview right after the base (and its attribute record) is a pixel
  // or a few (10 % of the first display's bytes): the texture's mean colour,
  // which on this checker is close to grey. The first display whose texture
  // can be seen is the one with the next level: find its record.
  auto index = read_stream_index(*stream);
  ASSERT_TRUE(index) << index.error().message;
  size_t first_level = 0;
  for (size_t i = 1; i < index->records.size() && first_level == 0; ++i) {
    const RecordEntry& r = index->records[i];
    auto level = read_texture_record(record_payload(r, {stream->data() + r.offset, r.size}));
    if (level && level->level > 0) first_level = i;
  }
  ASSERT_GT(first_level, 0u) << "a texture level after the preview";
  const auto first_hues = testing::saturated_by_hue(
      snapshot("first.png", {"--snapshot-at", std::to_string(first_level)}), 20);
  EXPECT_GT(testing::saturated_total(final_hues), 256 * 256 / 8);
  int present = 0;
  for (int c : final_hues) present += c > 200;
  EXPECT_GE(present, 3) << "red, green, blue, yellow: " << final_hues[0] << " " << final_hues[1]
                        << " " << final_hues[2] << " " << final_hues[3];
  EXPECT_GT(testing::saturated_total(first_hues), 256 * 256 / 16)
      << "the first texture level after the preview (record " << first_level
      << ") is textured when it arrives";

  // --out DIR --out-format glb: final.glb and final.decoded.glb, textured.
  {
    testing::ChildProcess client;
    EXPECT_TRUE(client.start({client_bin, address, "sphere", "--quiet", "--no-asa", "--out",
                              (dir / "glb").string(), "--out-format", "glb"},
                             (dir / "client.log").string()));
    EXPECT_EQ(client.wait(60s).value_or(-1), 0);
  }
  EXPECT_FALSE(fs::exists(dir / "glb" / "final.ply")) << "--out-format glb writes no PLY";
  const std::string modules = meshstream::testing::gltf_validator_modules();
  for (const char* name : {"final.glb", "final.decoded.glb"}) {
    const std::string path = (dir / "glb" / name).string();
    auto back = import_mesh(path);
    ASSERT_TRUE(back) << name << ": " << back.error().message;
    EXPECT_EQ(back->mesh.face_count(), decoded->face_count()) << name;
    EXPECT_EQ(back->mesh.textures.size(), 1u) << name << " carries the stream's texture";
    EXPECT_EQ(back->mesh.textures.empty() ? std::vector<uint8_t>{} : back->mesh.textures[0].bytes,
              decoded->textures[0].bytes)
        << name << ": the original image bytes";
    EXPECT_FALSE(back->mesh.texcoords.empty() && back->mesh.corner_texcoords.empty()) << name;
    if (modules.empty()) continue;
    const auto [status, out] = meshstream::testing::run_gltf_validator(modules, path);
    EXPECT_EQ(status, 0) << out;
    EXPECT_NE(out.find(": 0 errors"), std::string::npos) << out;
  }
  std::error_code ignored;
  fs::remove_all(dir, ignored);
  if (modules.empty())
    GTEST_SKIP()
        << "final.glb read back; the Khronos gltf-validator is not installed (scripts/test "
           "installs it into build/gltf-validator; set MESHSTREAM_GLTF_VALIDATOR)";
}

}  // namespace
}  // namespace meshstream::client
