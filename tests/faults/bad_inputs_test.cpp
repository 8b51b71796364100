// Regression tests for bad inputs found by the fuzzers (tests/fuzz): each
// must be refused with an error value, never crash the process.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "common/mesh/import.h"

namespace {

std::string write_temp(const std::string& name, const std::string& content) {
  const std::string path = (std::filesystem::temp_directory_path() / name).string();
  std::ofstream(path, std::ios::binary) << content;
  return path;
}

// fuzz_mesh_import, regressions/mesh_import/obj-face-*: an OBJ with a face
// but no `v` line made Draco's ObjDecoder dereference a missing position
// attribute (SEGV in draco::ObjDecoder::MapPointToVertexIndices): the
// server died importing such a file from --models.
TEST(BadInputs, ObjWithFacesButNoVerticesIsRefused) {
  for (const std::string content : {std::string("f 1 2 3\n"),
                                    std::string("\x01\0\0\0\0\0\0"
                                                "7 0 0 0\nf 6 2 1\n",
                                                23),
                                    std::string("vt 0 0\nvn 0 0 1\nf 1/1/1 1/1/1 1/1/1\n")}) {
    const std::string path =
        write_temp("meshstream-bad-input-" + std::to_string(::getpid()) + ".obj", content);
    auto imported = meshstream::import_mesh(path);
    std::remove(path.c_str());
    EXPECT_FALSE(imported.has_value()) << "an OBJ without vertices was accepted";
  }
}

}  // namespace
