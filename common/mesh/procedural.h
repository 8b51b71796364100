// Procedural meshes for tests, benchmarks and the demo: deterministic (same
// arguments, same bits on every machine with IEEE floats), manifold and
// consistently oriented (counter-clockwise seen from outside).
#pragma once

#include <cstdint>

#include "common/mesh/mesh.h"

namespace meshstream {

// The demo model: a trefoil (2,3 torus-knot) tube whose radius is displaced
// by features at several scales — a few broad bulges, ridges a tenth of the
// length apart, and fine gradient-noise bumps — so that coarse levels of a
// progressive stream already show the shape while the finest ones still add
// visible detail. Closed, one component, genus 1 (a knotted torus).
// About `target_faces` triangles (exactly 2 * U * V for the chosen grid);
// clamped to [384, 2^26]. O(faces).
Mesh make_demo_mesh(uint32_t target_faces = 100000);

// Regular icosahedron on the unit sphere: 12 vertices, 20 faces, genus 0.
Mesh make_icosahedron();

// Icosahedron split 1-to-4 `subdivisions` times, vertices pushed onto the
// unit sphere: 20 * 4^s faces, genus 0. `subdivisions` is clamped to 10.
Mesh make_icosphere(uint32_t subdivisions);

// n x n squares (two triangles each) on the unit square, gently waved in z:
// an open disc with 4n boundary edges in one loop, genus 0. n >= 1.
Mesh make_open_grid(uint32_t n);

// `count` closed icospheres (one subdivision, 80 faces each) in a row, each
// its own component: total genus 0, `count` components. count >= 1.
Mesh make_multi_component(uint32_t count);

// Torus with `major` segments around the axis and `minor` around the tube
// (both >= 3), radii 1 and 0.35: closed, genus 1, 2 * major * minor faces.
Mesh make_torus(uint32_t major = 48, uint32_t minor = 24);

// Meshes with seams (attributes.h), for the attribute work's tests.
//
// The cube [-1, 1]^3 with `segments` x `segments` quads per face (>= 1),
// positions welded along the cube's edges: closed, genus 0,
// 12 * segments^2 triangles, 6 * segments^2 + 2 vertices. Per-face normals as
// corner normals (each cube face's (segments + 1)^2 grid points have their
// own value, so 24 values at segments = 1: the cube's edges are normal
// seams), per-face texture coordinates (each face in its own cell of a
// 3 x 2 atlas: corner texcoords, the same value layout, no value shared
// between faces) and per-vertex colours (the
// position mapped from [-1, 1] to [0, 1], alpha 1).
Mesh make_faceted_cube(uint32_t segments = 1);

// Latitude-longitude unit sphere: `segments` meridians (>= 3) and `rings`
// latitude bands (>= 2), one vertex at each pole: closed, genus 0,
// 2 * segments * (rings - 1) triangles, segments * (rings - 1) + 2 vertices.
// Smooth per-vertex normals (the position). Texture coordinates per corner:
// u = longitude / 2pi, v = latitude band / rings, so the meridian u = 0 / 1
// is a seam (two values on each of its vertices), and each pole has one
// value per touching triangle (u at the middle of its segment).
Mesh make_uv_sphere(uint32_t segments = 32, uint32_t rings = 16);

}  // namespace meshstream
