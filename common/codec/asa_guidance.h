// Encoder-guided post-processing (issue 20, point 2): the encoder knows the
// original, so it measures which ASA setting (or none) brings each group of
// stream prefixes closest to it and writes that choice into the stream
// header; the client applies it by default (`--asa auto`).
//
// Why: no fixed setting is safe. The fidelity bench (bench/REPORT.md) found
// the old default ASA 1.01 dB worse than the plain prefix on average and
// 14.6 dB worse on a CAD part, the best fixed variant still 2.2 dB worse on
// one mesh, while smooth scans gain 1-2 dB. Which one wins depends on the
// mesh and on how much of it has arrived.
//
// In the stream (docs/hcs-format.md, "ASA guidance"): a header extension
// block after the refinement format's two bytes (extra[0], extra[1]):
//   u8 tag kAsaGuidanceTag, varint payload length, payload:
//   varint n (1 .. records), then n x (varint record delta, u8 choice)
// The first delta is the first record of the first group and must be 0;
// later deltas are at least 1 (groups start at strictly increasing
// records). Group g holds the prefixes that end at records
// [first_g, first_{g+1}). Readers skip blocks whose tag they do not know,
// so older decoders read a guided stream as before.
//
// A choice is one byte (asa_choice_options): bits 0-1 levels (0 = no ASA,
// then every other bit is 0), bits 2-3 flatness t (0.85, 0.90, 0.95, 0.75),
// bits 4-6 crease angle (none, 40, 45, 60, 75 degrees; 5-7 unused), bit 7
// the projection rule (else Zorin). A choice whose crease angle is below
// acos(t) (settings_check.h) is invalid: it would do nothing.
// Approximating choices (issue 20, point 4; written since the guidance has
// an approximating candidate): levels bits 0 and bit 7 set: the decoded
// positions relaxed by relax_toward_smooth (approximate.h; the crease angle,
// 60 degrees without one, as its sharp angle), then one level of Zorin ASA
// with bits 2-6's flatness and crease angle. Older
// readers refuse such a byte ("no levels") and so the whole guidance: they
// show the decoded mesh, the safe default, never the ASA step alone.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "common/asa/approximate.h"
#include "common/asa/subdivide.h"
#include "common/base/result.h"
#include "common/codec/container.h"
#include "common/mesh/mesh.h"
#include "common/metrics/bvh.h"

namespace meshstream {

inline constexpr uint8_t kAsaGuidanceTag = 0x41;  // 'A'
inline constexpr uint8_t kAsaChoiceOff = 0;

// The ASA options of a choice byte: nullopt for "no ASA"; an error
// (kCorrupt, naming the byte) for a byte no choice has.
Result<std::optional<AsaOptions>> asa_choice_options(uint8_t choice);
// The choice byte of `options` (levels 1-3, and a flatness, crease and
// rule the byte can hold), or nullopt.
std::optional<uint8_t> asa_choice_of(const AsaOptions& options);
// "off" or e.g. "L1 t0.85 crease45": for reports and events.
std::string asa_choice_label(uint8_t choice);

// Whether `choice` is an approximating one (relax_toward_smooth, then ASA);
// false for off, interpolating and invalid bytes.
bool asa_choice_approximates(uint8_t choice);
// The approximating choice of an interpolating one-level Zorin choice (its
// flatness and crease angle), or nullopt.
std::optional<uint8_t> approximating_choice(uint8_t choice);
// The relaxation an approximating choice runs before its ASA step.
RelaxOptions asa_choice_relax(const AsaOptions& asa_step);
// The mesh `choice` shows for `prefix`: the prefix itself (off), its ASA
// subdivision, or the subdivision of the relaxed prefix. kCorrupt for an invalid byte; ASA's and
// the relaxation's errors. With track_source_faces when `source_face` is given.
Result<Mesh> apply_asa_choice(const Mesh& prefix, uint8_t choice,
                              std::vector<uint32_t>* source_face = nullptr);

struct AsaGuidanceGroup {
  uint32_t first_record = 0;  // the group's prefixes end at this record or later
  uint8_t choice = kAsaChoiceOff;
};

struct AsaGuidance {
  std::vector<AsaGuidanceGroup> groups;  // first_record strictly increasing, first 0
  // The choice for a prefix of `records_decoded` records (the last one
  // applied is records_decoded - 1). Precondition: groups not empty.
  uint8_t choice_for(uint32_t records_decoded) const;
};

// The header extension block carrying `guidance`, appended to `extra`
// (after extra[0], extra[1]; the caller makes sure those two exist).
void append_asa_guidance(std::vector<uint8_t>& extra, const AsaGuidance& guidance);

// Reads the guidance block of a stream header, if any: nullopt for a
// stream without one (older encoders, --no-asa-guidance). kCorrupt, naming
// the problem, for a block that does not parse, a group past
// `record_count`, a first group not at record 0, records not increasing,
// or an invalid choice byte: such guidance is never applied (the caller
// falls back to its safe default). O(extra bytes).
Result<std::optional<AsaGuidance>> read_asa_guidance(const StreamHeader& header,
                                                     uint32_t record_count);

struct AsaGuidanceOptions {
  // Groups: a prefix's compression ratio (stream bytes / prefix bytes) is
  // binned into 2^(1/groups_per_octave) steps; each group is measured once,
  // at the prefix nearest the middle of its bin.
  int groups_per_octave = 1;
  // Prefixes coarser than this ratio share the coarsest group.
  double max_ratio = 128;
  // ASA must lower the measured RMS distance by this share to be chosen
  // over no ASA (a margin for what the distance does not see).
  double margin = 0.02;
  // Once a group measured at a ratio below this chose no ASA, the finer
  // groups get none without being measured (0: measure every group).
  double stop_below_ratio = 16;
  // Area samples on the original, and about as many quadrature points on
  // a fixed subset of each prefix's faces: noise well below the margin.
  uint32_t samples = 16000;
  // A prefix with more faces is measured at about this many of them (a
  // well-spread subset, the same for each candidate) and their
  // neighbourhoods, with the original's samples near them.
  uint32_t probe_faces = 4000;
  // ASA must also lower the shading deviation (mean 1 - cos between the
  // original's and the shown surface's shading normals, made as the
  // client's renderer makes them) by this share: pictures are shaded, and
  // distance alone can improve while the picture gets worse (casting at
  // ratio 10: 0.92x the RMS, 1.04x the shading deviation, -0.40 dB).
  // Negative: distance alone decides.
  double shading_margin = 0.02;
  // Threads for the closest-point queries and the hierarchies (0 = one
  // per core); the choices are the same for every count.
  unsigned threads = 1;
  // A hierarchy over the original (its triangles and positions, e.g. the
  // encoder's, refitted: TriangleBvh::refit), used instead of building
  // one; it must outlive the call. Empty or null: built here.
  const TriangleBvh* original_hierarchy = nullptr;
  // Called with the share of the measurement done; empty = no calls.
  std::function<void(double)> progress;
  // Where an interpolating one-level candidate won, also try it on the
  // relaxed prefix (its approximating choice): chosen by the same rule, and
  // only when it is closer than that candidate by the margin too.
  bool approximate = true;
  // ... at groups measured at this ratio or coarser: the option is for
  // coarse prefixes (on the 12 bench meshes it never beat its interpolating
  // setting by the margin at any ratio, bench/REPORT.md), and the finer
  // groups' measurements cost the most.
  double approximate_above_ratio = 16;
  // A group's choice is shown at every prefix in it, down to its finest,
  // where ASA's gain is smallest (the prefix has filled in): the winner must
  // qualify at the group's finest prefix too, else the group gets none. One
  // more measurement per group that chose ASA (the middle prefix alone chose
  // ASA on casting at ratio 11, whose default view then lost 0.46 dB at
  // ratio 10 while the finest prefix, ratio 5.6, measured a shading loss).
  bool check_finest_end = true;
  // The settings tried, as choice bytes; off is always tried.
  std::vector<uint8_t> candidates = default_candidates();
  static std::vector<uint8_t> default_candidates();
};

// What the measurement found (for the encoder's report and the bench).
struct AsaGuidanceReport {
  struct Group {
    uint32_t first_record = 0, measured_record = 0;
    double ratio = 0;            // of the measured prefix
    std::vector<double> rms;     // per candidate (off first), relative to the diagonal
    std::vector<double> normal;  // per candidate (off first): shading deviation (0: not measured)
    // The winner's approximating choice, when one was measured (else 0).
    double approximate_rms = 0, approximate_normal = 0;
    // The winner at the group's finest prefix (check_finest_end; else 0):
    // its ratio, and the winner's RMS and shading deviation there relative
    // to the plain prefix's.
    double finest_ratio = 0, finest_rms_ratio = 0, finest_normal_ratio = 0;
    uint8_t choice = kAsaChoiceOff;
    uint32_t prefix_faces = 0;
    double seconds = 0;  // decoding up to it and measuring it
  };
  std::vector<Group> groups;
  double seconds = 0;
};

// Measures the guidance of an encoded `stream` of `original`: decodes the
// stream once, record by record (up to where stop_below_ratio ends it), and
// at each group's measured prefix
// applies every candidate and measures the symmetric RMS surface distance
// to the original (RdMeasure). The complete stream gets no ASA (nothing is
// missing). Groups with equal choices are merged. Fails with the decoder's
// or ASA's error. Cost: one decode, plus per group one distance per
// candidate (a hierarchy over the candidate's mesh and its queries).
Result<AsaGuidance> measure_asa_guidance(const Mesh& original, std::span<const uint8_t> stream,
                                         const AsaGuidanceOptions& options = {},
                                         AsaGuidanceReport* report = nullptr);

// `stream` with its header's guidance block set to `guidance` (an older
// block replaced): magic, version and flags kept, header and its CRC
// rewritten, index and records copied. Fails as read_stream_index does.
Result<std::vector<uint8_t>> with_asa_guidance(std::span<const uint8_t> stream,
                                               const AsaGuidance& guidance);

}  // namespace meshstream
