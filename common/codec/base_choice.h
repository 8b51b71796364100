// Choosing how the base mesh is coded: the traversal coder (base_coder.h)
// or Draco, whichever is smaller. Draco reorders vertices, so a Draco base is
// kept only when its decode can be mapped back onto exactly the decimated
// base; its decoded order then becomes the base order the refinement
// records name vertices by.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "common/codec/base_coder.h"
#include "common/codec/decimate.h"
#include "common/codec/quantize.h"

namespace meshstream {

struct ChosenBase {
  uint8_t coder = kBaseCoderOwn;
  std::vector<uint8_t> bytes;
  BaseMesh decoded;                // what the decoder will start from
  std::vector<uint32_t> to_input;  // decoded vertex -> input vertex id
};

// The base of `dec` through the old own coder (kBaseCoderOwn, what encoder
// versions up to 8 wrote), with vertices in order of first use by the faces.
// `positions` by input vertex id. O(base size). Always exact: the fallback
// when the traversal coder refuses a base.
ChosenBase code_base_own(const DecimationResult& dec, const std::vector<Vec3i>& positions);

// The base of `dec` through the traversal coder (kBaseCoderTraversal) at
// `bits` per axis, in the order its decoder gives; empty when the base is
// not an oriented manifold. O(base size).
std::optional<ChosenBase> code_base_traversal(const DecimationResult& dec,
                                              const std::vector<Vec3i>& positions, int bits);

// The base of `dec` through Draco at `bits` per axis, accepted only when
// its decode gives back exactly our base (same grid points, same oriented
// faces); empty when Draco fails or its decode cannot be mapped back.
std::optional<ChosenBase> code_base_draco(const DecimationResult& dec,
                                          const std::vector<Vec3i>& positions, int bits);

// The smaller of the traversal coder's and Draco's (the traversal coder
// when Draco is not allowed, fails, or is not smaller; the old own coder
// when the traversal coder refuses). `positions` are the coarse grid points (`bits` per
// axis) by input vertex id.
ChosenBase choose_base(const DecimationResult& dec, const std::vector<Vec3i>& positions, int bits,
                       bool allow_draco);

}  // namespace meshstream
