// Corner-table invariants on every real mesh after import (repaired where
// needed) and on the procedural meshes.
#include <gtest/gtest.h>

#include "common/mesh/import.h"
#include "common/mesh/procedural.h"
#include "tests/mesh/mesh_invariants.h"
#include "tests/test_meshes.h"

namespace meshstream {
namespace {

const char* kImportable[] = {"bun_zipper.ply",
                             "bunny.off",
                             "bunny.stl",
                             "armadillo.obj",
                             "fandisk.off",
                             "crank.off",
                             "casting.off",
                             "mask.off",
                             "hemisphere.off",
                             "skull.obj",
                             "maneki-neko.off",
                             "dragon_res2.ply",
                             "dragon_res3.ply",
                             "sphere.obj",
                             "sphere_low.off",
                             "chamfer-cube.off",
                             "cube_att.obj",
                             "cube_quads.obj",
                             "octagon.obj",
                             "multiple_isolated_triangles.obj",
                             "multiple_tetrahedrons.obj",
                             "suzanne.obj",
                             "test_nm.obj",
                             "non_manifold_wrap.obj",
                             "deg_faces.obj",
                             "extra_vertex.obj",
                             "eof_test.obj"};

TEST(AdjacencyInvariants, EveryImportedRealMesh) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  for (const char* name : kImportable) {
    auto imported = import_mesh(testing::test_mesh(name));
    ASSERT_TRUE(imported) << name << ": " << imported.error().message;
    testing::expect_adjacency_invariants(imported->mesh, name);
  }
}

TEST(AdjacencyInvariants, ProceduralMeshes) {
  testing::expect_adjacency_invariants(make_icosahedron(), "icosahedron");
  testing::expect_adjacency_invariants(make_icosphere(3), "icosphere");
  testing::expect_adjacency_invariants(make_open_grid(7), "grid");
  testing::expect_adjacency_invariants(make_multi_component(4), "components");
  testing::expect_adjacency_invariants(make_torus(12, 7), "torus");
  testing::expect_adjacency_invariants(make_demo_mesh(5000), "demo");
}

}  // namespace
}  // namespace meshstream
