// The traversal base coder (kBaseCoderTraversal): see base_coder.h.
//
// Faces are visited breadth first across edges, from a seed face per
// component. The encoder and the decoder keep the same picture of what is
// decoded so far (Traversal), so every symbol is one both sides can read in
// the same place:
// - for each edge (a, b) of a face taken from the queue whose twin (b, a) is
//   not decoded yet, one bit: is there a face across it;
// - for such a face (b, a, x), how x is named: a new vertex, the open
//   neighbour of a or of b in the decoded part (closing a fan: the common
//   case), or an explicit index;
// - a seed face names its corners as new vertices or explicit indices;
//   vertices in no face come last.
// Vertices are numbered in order of first appearance: the decoder's order,
// which the encoder adopts (as it adopts Draco's). Then the positions, in
// that order, with the whole connectivity known (as Draco's): the mean of
// every parallelogram y + z - w over the vertex's faces (v, y, z) whose
// neighbour across (y, z) has its third corner w decoded, else the delta
// from a decoded neighbour, else from the previous vertex; the residuals
// through adaptive models per axis and per kind of prediction.
#include <algorithm>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "common/codec/base_coder.h"
#include "common/codec/byte_io.h"
#include "common/codec/range_coder.h"
#include "common/mesh/adjacency.h"

namespace meshstream {
namespace {

constexpr uint32_t kThirdNew = 0;    // a vertex not seen before
constexpr uint32_t kThirdLeft = 1;   // the open neighbour of a
constexpr uint32_t kThirdRight = 2;  // the open neighbour of b
constexpr uint32_t kThirdIndex = 3;  // named by index

uint64_t edge_key(uint32_t a, uint32_t b) { return uint64_t(a) << 32 | b; }

struct TraversalModels {
  BitModel gate;                    // is there a face across this edge
  BitTreeModel<2, BitModel> third;  // how a gate face's third corner is named
  BitModel seed_corner_new;         // a seed face's corner is a new vertex
  AdaptiveUIntModel index;          // count - 1 - id of an old vertex named by index
};

// Residual models by how the position was predicted.
struct PositionModels {
  AdaptiveIntModel parallelogram[3];
  AdaptiveIntModel neighbour[3];
  AdaptiveIntModel jump[3];
};

// What both sides know: the vertices and faces decoded so far (new ids),
// their directed edges, and each vertex's incoming and outgoing edges.
class Traversal {
 public:
  std::vector<Triangle> faces;

  uint32_t vertex_count() const { return static_cast<uint32_t>(in_.size()); }
  uint32_t add_vertex() {
    in_.emplace_back();
    out_.emplace_back();
    return vertex_count() - 1;
  }
  bool has_edge(uint32_t a, uint32_t b) const { return edges_.count(edge_key(a, b)) != 0; }
  // The third corner of the face with the directed edge (a, b), or kNone.
  uint32_t third(uint32_t a, uint32_t b) const {
    const auto it = edges_.find(edge_key(a, b));
    return it == edges_.end() ? kNone : it->second;
  }
  // False when the face repeats a vertex or a directed edge (not an
  // oriented manifold): a corrupt record, or a base this coder cannot carry.
  bool add_face(const Triangle& t) {
    if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) return false;
    for (int i = 0; i < 3; ++i)
      if (has_edge(t[i], t[(i + 1) % 3])) return false;
    for (int i = 0; i < 3; ++i) {
      const uint32_t u = t[i], w = t[(i + 1) % 3];
      edges_.emplace(edge_key(u, w), t[(i + 2) % 3]);
      out_[u].push_back(w);
      in_[w].push_back(u);
    }
    faces.push_back(t);
    return true;
  }
  // The face across (a, b) is (b, a, x). When x closes a fan, the decoded
  // part already has the edge x -> a (open: no a -> x yet) or b -> x.
  uint32_t left_of(uint32_t a, uint32_t b) const {
    for (uint32_t y : in_[a])
      if (y != b && !has_edge(a, y)) return y;
    return kNone;
  }
  uint32_t right_of(uint32_t a, uint32_t b) const {
    for (uint32_t y : out_[b])
      if (y != a && !has_edge(y, b)) return y;
    return kNone;
  }

 private:
  std::unordered_map<uint64_t, uint32_t> edges_;  // directed edge -> third corner
  std::vector<std::vector<uint32_t>> in_, out_;
};

// How vertex v's position is predicted from the vertices before it (all
// faces known): its prediction and the models its residual goes through.
class PositionPredictor {
 public:
  // `vertices`: those of the traversal and those in no face after them.
  PositionPredictor(const Traversal& tr, uint32_t vertices, int quant_bits)
      : tr_(tr), max_((int32_t(1) << quant_bits) - 1), first_(size_t(vertices) + 1, 0) {
    for (const Triangle& t : tr.faces)
      for (uint32_t v : t) ++first_[v + 1];
    for (size_t v = 0; v < vertices; ++v) first_[v + 1] += first_[v];
    faces_.resize(first_[vertices]);
    std::vector<uint32_t> fill(first_.begin(), first_.end() - 1);
    for (uint32_t f = 0; f < tr.faces.size(); ++f)
      for (uint32_t v : tr.faces[f]) faces_[fill[v]++] = f;
  }
  // positions[0..v) are known.
  Vec3i predict(uint32_t v, const std::vector<Vec3i>& positions, PositionModels& m,
                AdaptiveIntModel (*&models)[3]) const {
    int64_t sum[3] = {0, 0, 0};
    int64_t count = 0;
    uint32_t neighbour = kNone;
    for (uint32_t i = first_[v]; i < first_[v + 1]; ++i) {
      const Triangle& t = tr_.faces[faces_[i]];
      const int at = t[0] == v ? 0 : t[1] == v ? 1 : 2;
      const uint32_t y = t[(at + 1) % 3], z = t[(at + 2) % 3];
      if (y < v && neighbour == kNone) neighbour = y;
      if (y >= v || z >= v) continue;
      const uint32_t w = tr_.third(z, y);  // across (y, z)
      if (w == kNone || w >= v) continue;
      for (int i = 0; i < 3; ++i)
        sum[i] += int64_t(positions[y][i]) + positions[z][i] - positions[w][i];
      ++count;
    }
    if (count > 0) {
      models = &m.parallelogram;
      Vec3i p;
      for (int i = 0; i < 3; ++i)
        p[i] = static_cast<int32_t>(std::clamp<int64_t>(sum[i] / count, 0, max_));
      return p;
    }
    if (neighbour != kNone) {
      models = &m.neighbour;
      return positions[neighbour];
    }
    models = &m.jump;
    return v > 0 ? positions[v - 1] : Vec3i{};
  }

 private:
  const Traversal& tr_;
  const int32_t max_;
  std::vector<uint32_t> first_, faces_;  // v's faces: faces_[first_[v] .. first_[v + 1])
};

}  // namespace

Result<TraversalCodedBase> encode_base_traversal(const BaseMesh& base, int quant_bits) {
  const uint32_t nv = static_cast<uint32_t>(base.positions.size());
  const uint32_t nf = static_cast<uint32_t>(base.faces.size());
  auto cannot = [](const std::string& why) {
    return make_error(ErrorCode::kUnsupported, "traversal base coder: " + why);
  };
  std::unordered_map<uint64_t, uint32_t> face_of_edge;  // base ids
  for (uint32_t f = 0; f < nf; ++f) {
    const Triangle& t = base.faces[f];
    for (int i = 0; i < 3; ++i) {
      if (t[i] >= nv) return cannot("face index out of range");
      if (!face_of_edge.emplace(edge_key(t[i], t[(i + 1) % 3]), f).second)
        return cannot("a directed edge in two faces");
    }
  }
  TraversalCodedBase out;
  put_varint(out.bytes, nv);
  put_varint(out.bytes, nf);
  RangeEncoder enc;
  TraversalModels m;
  Traversal tr;
  std::vector<uint32_t> new_id(nv, kNone);
  std::vector<uint8_t> visited(nf, 0);
  auto name = [&](uint32_t v) {  // the new id of v, named now if new
    if (new_id[v] == kNone) {
      new_id[v] = tr.add_vertex();
      out.to_base.push_back(v);
    }
    return new_id[v];
  };
  uint32_t next_seed = 0;
  size_t head = 0;
  while (tr.faces.size() < nf) {
    while (visited[next_seed]) ++next_seed;
    visited[next_seed] = 1;
    Triangle seed;
    for (int i = 0; i < 3; ++i) {
      const uint32_t v = base.faces[next_seed][i];
      const bool fresh = new_id[v] == kNone;
      enc.encode_bit(m.seed_corner_new, fresh ? 1 : 0);
      if (!fresh) m.index.encode(enc, tr.vertex_count() - 1 - new_id[v]);
      seed[i] = name(v);
    }
    if (!tr.add_face(seed)) return cannot("a face repeats a vertex or an edge");
    while (head < tr.faces.size()) {
      const Triangle g = tr.faces[head++];
      for (int i = 0; i < 3; ++i) {
        const uint32_t a = g[i], b = g[(i + 1) % 3];
        if (tr.has_edge(b, a)) continue;
        const auto across = face_of_edge.find(edge_key(out.to_base[b], out.to_base[a]));
        enc.encode_bit(m.gate, across != face_of_edge.end() ? 1 : 0);
        if (across == face_of_edge.end()) continue;
        const uint32_t f = across->second;
        if (visited[f]) return cannot("a face reached twice");
        visited[f] = 1;
        uint32_t x = kNone;
        for (uint32_t v : base.faces[f])
          if (v != out.to_base[a] && v != out.to_base[b]) x = v;
        if (x == kNone) return cannot("a face repeats a vertex");
        if (new_id[x] == kNone) {
          m.third.encode(enc, kThirdNew);
        } else if (new_id[x] == tr.left_of(a, b)) {
          m.third.encode(enc, kThirdLeft);
        } else if (new_id[x] == tr.right_of(a, b)) {
          m.third.encode(enc, kThirdRight);
        } else {
          m.third.encode(enc, kThirdIndex);
          m.index.encode(enc, tr.vertex_count() - 1 - new_id[x]);
        }
        if (!tr.add_face({b, a, name(x)})) return cannot("a face repeats a vertex or an edge");
      }
    }
  }
  for (uint32_t v = 0; v < nv; ++v) {  // vertices in no face
    if (new_id[v] != kNone) continue;
    new_id[v] = static_cast<uint32_t>(out.to_base.size());
    out.to_base.push_back(v);
  }
  std::vector<Vec3i> positions;
  positions.reserve(nv);
  const PositionPredictor predictor(tr, nv, quant_bits);
  PositionModels pm;
  for (uint32_t v = 0; v < nv; ++v) {
    AdaptiveIntModel(*models)[3] = nullptr;
    const Vec3i pred = predictor.predict(v, positions, pm, models);
    const Vec3i p = base.positions[out.to_base[v]];
    for (int i = 0; i < 3; ++i) (*models)[i].encode(enc, p[i] - pred[i]);
    positions.push_back(p);
  }
  const std::vector<uint8_t> coded = enc.finish();
  out.bytes.insert(out.bytes.end(), coded.begin(), coded.end());
  out.decoded.positions = std::move(positions);
  out.decoded.faces = std::move(tr.faces);
  return out;
}

Result<BaseMesh> decode_base_traversal(std::span<const uint8_t> bytes, uint32_t vertex_count,
                                       uint32_t face_count, int quant_bits) {
  auto corrupt = [](const std::string& why) {
    return make_error(ErrorCode::kCorrupt, "traversal-coded base mesh: " + why);
  };
  size_t pos = 0;
  uint32_t nv = 0, nf = 0;
  if (!get_varint(bytes, pos, nv) || !get_varint(bytes, pos, nf))
    return corrupt("counts cut short");
  if (nv != vertex_count || nf != face_count) {
    return corrupt("it has " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
                   " faces, the header says " + std::to_string(vertex_count) + " and " +
                   std::to_string(face_count));
  }
  const int32_t max = (int32_t(1) << quant_bits) - 1;
  RangeDecoder dec(bytes.subspan(pos));
  TraversalModels m;
  Traversal tr;
  // Every loop below adds a vertex or a face and stops once the bytes have
  // run out: a hostile count cannot make it allocate beyond what the record
  // holds.
  auto fresh = [&]() -> Result<uint32_t> {
    if (tr.vertex_count() >= nv) return corrupt("more vertices than the header's");
    return tr.add_vertex();
  };
  auto read_index = [&]() -> Result<uint32_t> {
    const uint32_t back = m.index.decode(dec);
    if (back >= tr.vertex_count()) return corrupt("vertex index out of range");
    return tr.vertex_count() - 1 - back;
  };
  size_t head = 0;
  while (tr.faces.size() < nf) {
    if (dec.exhausted_badly()) return corrupt("data ends early");
    Triangle seed;
    for (int i = 0; i < 3; ++i) {
      auto v = dec.decode_bit(m.seed_corner_new) ? fresh() : read_index();
      if (!v) return tl::unexpected(v.error());
      seed[i] = *v;
    }
    if (!tr.add_face(seed)) return corrupt("a face repeats a vertex or an edge");
    while (head < tr.faces.size()) {
      if (dec.exhausted_badly()) return corrupt("data ends early");
      const Triangle g = tr.faces[head++];
      for (int i = 0; i < 3; ++i) {
        const uint32_t a = g[i], b = g[(i + 1) % 3];
        if (tr.has_edge(b, a)) continue;
        if (!dec.decode_bit(m.gate)) continue;
        if (tr.faces.size() >= nf) return corrupt("more faces than the header's");
        Result<uint32_t> x = kNone;
        switch (m.third.decode(dec)) {
          case kThirdNew:
            x = fresh();
            break;
          case kThirdLeft:
            x = tr.left_of(a, b);
            break;
          case kThirdRight:
            x = tr.right_of(a, b);
            break;
          default:
            x = read_index();
        }
        if (!x) return tl::unexpected(x.error());
        if (*x == kNone) return corrupt("a fan to close where none is open");
        if (!tr.add_face({b, a, *x})) return corrupt("a face repeats a vertex or an edge");
      }
    }
  }
  if (dec.exhausted_badly()) return corrupt("data ends early");
  // Vertices in no face: as many as the header has left. Each position
  // costs at least 3 model bits of about 1/45 bit, so a record holds fewer
  // than 128 of them per byte: refuse more before sizing anything by them.
  if (uint64_t(nv - tr.vertex_count()) > uint64_t(bytes.size()) * 128)
    return corrupt("more vertices than its bytes can hold");
  std::vector<Vec3i> positions;  // grows as read: the loop stops when the bytes run out
  const PositionPredictor predictor(tr, nv, quant_bits);
  PositionModels pm;
  for (uint32_t v = 0; v < nv; ++v) {
    if (dec.exhausted_badly()) return corrupt("data ends early");
    AdaptiveIntModel(*models)[3] = nullptr;
    const Vec3i pred = predictor.predict(v, positions, pm, models);
    Vec3i p;
    for (int i = 0; i < 3; ++i) {
      const int64_t c = pred[i] + (*models)[i].decode(dec);
      if (c < 0 || c > max) return corrupt("vertex outside the grid");
      p[i] = static_cast<int32_t>(c);
    }
    positions.push_back(p);
  }
  if (dec.exhausted_badly()) return corrupt("data ends early");
  BaseMesh base;
  base.positions = std::move(positions);
  base.faces = std::move(tr.faces);
  return base;
}

}  // namespace meshstream
