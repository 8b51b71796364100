#include "common/codec/asa_guidance.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "common/asa/settings_check.h"
#include "common/codec/byte_io.h"
#include "common/codec/crc32.h"
#include "common/codec/decoder.h"
#include "common/codec/rd_measure.h"

namespace meshstream {
namespace {

constexpr float kFlatness[4] = {0.85f, 0.90f, 0.95f, 0.75f};
constexpr float kCrease[5] = {0, 40, 45, 60, 75};
// The refinement format's own header bytes come first (extra[0], extra[1]).
constexpr size_t kExtensionsAt = 2;

Error corrupt(const std::string& what) {
  return Error{ErrorCode::kCorrupt, ".hcs ASA guidance: " + what};
}

uint8_t make_choice(int levels, int flatness_index, int crease_index, bool projection) {
  return static_cast<uint8_t>(levels | flatness_index << 2 | crease_index << 4 |
                              (projection ? 0x80 : 0));
}

// Where the guidance block sits in `extra`: [begin, end) of the whole
// block (tag, length, payload) and the payload; nullopt when absent.
struct BlockSpan {
  size_t begin = 0, payload = 0, end = 0;
};
Result<std::optional<BlockSpan>> find_block(const std::vector<uint8_t>& extra) {
  size_t pos = kExtensionsAt;
  while (pos < extra.size()) {
    BlockSpan span;
    span.begin = pos;
    const uint8_t tag = extra[pos++];
    uint32_t length = 0;
    if (!get_varint(extra, pos, length) || length > extra.size() - pos)
      return tl::unexpected(
          corrupt("header extension block " + std::to_string(tag) + " runs past the header"));
    span.payload = pos;
    span.end = pos + length;
    if (tag == kAsaGuidanceTag) return std::optional<BlockSpan>(span);
    pos = span.end;  // a block this build does not know
  }
  return std::optional<BlockSpan>();
}

}  // namespace

std::vector<uint8_t> AsaGuidanceOptions::default_candidates() {
  // L1 t0.85 (the old fixed default), with creases at 45 and 60 degrees (the
  // bench's best fixed variant and a gentler one), and t0.95 with creases.
  // Two levels (t0.85, crease 45) were tried too and never chosen on the 12
  // real meshes (bench/REPORT.md, fidelity), at the highest cost.
  return {make_choice(1, 0, 0, false), make_choice(1, 0, 2, false), make_choice(1, 0, 3, false),
          make_choice(1, 2, 2, false)};
}

Result<std::optional<AsaOptions>> asa_choice_options(uint8_t choice) {
  if (choice == kAsaChoiceOff) return std::optional<AsaOptions>();
  const int levels = choice & 3;
  const int flatness = (choice >> 2) & 3;
  const int crease = (choice >> 4) & 7;
  char hex[8];
  std::snprintf(hex, sizeof hex, "0x%02x", choice);
  if (levels == 0) return tl::unexpected(corrupt(std::string("choice ") + hex + " has no levels"));
  if (crease >= int(std::size(kCrease)))
    return tl::unexpected(corrupt(std::string("choice ") + hex + " has no such crease angle"));
  AsaOptions o;
  o.levels = levels;
  o.flatness = kFlatness[flatness];
  o.crease_degrees = kCrease[crease];
  o.rule = (choice & 0x80) ? ButterflyRule::kProjection : ButterflyRule::kZorin;
  if (!asa_settings_problem(o, "crease", "flatness").empty())
    return tl::unexpected(
        corrupt(std::string("choice ") + hex + " has a crease angle below acos(t)"));
  return std::optional<AsaOptions>(o);
}

std::optional<uint8_t> asa_choice_of(const AsaOptions& o) {
  if (o.levels < 1 || o.levels > 3 || o.uniform || o.tension != 0 || o.view.enabled)
    return std::nullopt;
  const auto f = std::find(std::begin(kFlatness), std::end(kFlatness), o.flatness);
  const auto c = std::find(std::begin(kCrease), std::end(kCrease), o.crease_degrees);
  if (f == std::end(kFlatness) || c == std::end(kCrease)) return std::nullopt;
  const uint8_t choice =
      make_choice(o.levels, int(f - std::begin(kFlatness)), int(c - std::begin(kCrease)),
                  o.rule == ButterflyRule::kProjection);
  if (!asa_choice_options(choice)) return std::nullopt;
  return choice;
}

std::string asa_choice_label(uint8_t choice) {
  auto o = asa_choice_options(choice);
  if (!o) return "invalid";
  if (!*o) return "off";
  char text[80];
  std::snprintf(text, sizeof text, "L%d t%.2f", (*o)->levels, double((*o)->flatness));
  std::string label = text;
  if ((*o)->crease_degrees > 0) label += " crease" + std::to_string(int((*o)->crease_degrees));
  if ((*o)->rule == ButterflyRule::kProjection) label += " projection";
  return label;
}

uint8_t AsaGuidance::choice_for(uint32_t records_decoded) const {
  const uint32_t last = records_decoded > 0 ? records_decoded - 1 : 0;
  uint8_t choice = groups.front().choice;
  for (const AsaGuidanceGroup& g : groups) {
    if (g.first_record > last) break;
    choice = g.choice;
  }
  return choice;
}

void append_asa_guidance(std::vector<uint8_t>& extra, const AsaGuidance& guidance) {
  std::vector<uint8_t> payload;
  put_varint(payload, static_cast<uint32_t>(guidance.groups.size()));
  uint32_t previous = 0;
  for (const AsaGuidanceGroup& g : guidance.groups) {
    put_varint(payload, g.first_record - previous);
    payload.push_back(g.choice);
    previous = g.first_record;
  }
  extra.push_back(kAsaGuidanceTag);
  put_varint(extra, static_cast<uint32_t>(payload.size()));
  extra.insert(extra.end(), payload.begin(), payload.end());
}

Result<std::optional<AsaGuidance>> read_asa_guidance(const StreamHeader& header,
                                                     uint32_t record_count) {
  auto span = find_block(header.extra);
  if (!span) return tl::unexpected(span.error());
  if (!*span) return std::optional<AsaGuidance>();
  const std::span<const uint8_t> payload(header.extra.data() + (*span)->payload,
                                         (*span)->end - (*span)->payload);
  size_t pos = 0;
  uint32_t n = 0;
  if (!get_varint(payload, pos, n) || n == 0 || n > record_count)
    return tl::unexpected(corrupt("implausible group count"));
  AsaGuidance g;
  uint32_t record = 0;
  for (uint32_t i = 0; i < n; ++i) {
    uint32_t delta = 0;
    if (!get_varint(payload, pos, delta) || pos >= payload.size())
      return tl::unexpected(corrupt("group " + std::to_string(i) + " is cut short"));
    if (i == 0 ? delta != 0 : delta == 0)
      return tl::unexpected(
          corrupt(i == 0 ? "the first group does not start at record 0"
                         : "group " + std::to_string(i) + " does not start after the one before"));
    if (delta >= record_count - record)
      return tl::unexpected(corrupt("group " + std::to_string(i) + " starts past the last record"));
    record += delta;
    const uint8_t choice = payload[pos++];
    if (auto o = asa_choice_options(choice); !o) return tl::unexpected(o.error());
    g.groups.push_back({record, choice});
  }
  if (pos != payload.size()) return tl::unexpected(corrupt("bytes after the last group"));
  return std::optional<AsaGuidance>(std::move(g));
}

Result<AsaGuidance> measure_asa_guidance(const Mesh& original, std::span<const uint8_t> stream,
                                         const AsaGuidanceOptions& options,
                                         AsaGuidanceReport* report) {
  const auto start = std::chrono::steady_clock::now();
  auto index = read_stream_index(stream);
  if (!index) return tl::unexpected(index.error());
  const std::vector<RecordEntry>& records = index->records;
  const uint32_t n = static_cast<uint32_t>(records.size());
  if (n == 0) return make_error(ErrorCode::kInvalidArgument, "ASA guidance: stream has no records");
  const double total = double(index->total_bytes());
  const int per_octave = std::max(1, options.groups_per_octave);
  const int coarsest = int(std::floor(std::log2(std::max(options.max_ratio, 1.0)) * per_octave));
  auto bin_of = [&](uint32_t i) {
    const double ratio = total / double(records[i].offset + records[i].size);
    return std::clamp(int(std::floor(std::log2(ratio) * per_octave)), 0, coarsest);
  };
  auto ratio_of = [&](uint32_t i) { return total / double(records[i].offset + records[i].size); };

  // Groups: runs of records in one bin, the complete stream on its own.
  struct Planned {
    uint32_t first, measured;
  };
  std::vector<Planned> planned;
  for (uint32_t i = 0; i + 1 < n;) {
    const int bin = bin_of(i);
    const double middle = std::pow(2.0, (bin + 0.5) / per_octave);
    uint32_t j = i, best = i;
    for (; j + 1 < n && bin_of(j) == bin; ++j) {
      if (std::abs(std::log(ratio_of(j) / middle)) < std::abs(std::log(ratio_of(best) / middle)))
        best = j;
    }
    planned.push_back({i, best});
    i = j;
  }

  RdMeasureOptions mopt;
  mopt.samples = options.samples;
  auto measure = RdMeasure::prepare(original, mopt);
  if (!measure) return tl::unexpected(measure.error());
  std::vector<AsaOptions> candidate_options;
  for (uint8_t c : options.candidates) {
    auto o = asa_choice_options(c);
    if (!o || !*o)
      return make_error(
          ErrorCode::kInvalidArgument,
          "ASA guidance: candidate " + asa_choice_label(c) + " is not an ASA setting");
    candidate_options.push_back(**o);
  }

  AsaGuidance guidance;
  IncrementalDecoder decoder;
  AsaWorkspace workspace;
  AsaResult out;
  uint64_t fed = 0;
  double report_last_ratio = 0;  // of the last group measured
  for (const Planned& p : planned) {
    // ASA's gain shrinks as the prefix fills in: once a group as fine as
    // stop_below_ratio chose none, the finer ones are not measured (none
    // of the bench's meshes chose ASA finer than such a group, and the
    // finest groups cost the most).
    if (!guidance.groups.empty() && guidance.groups.back().choice == kAsaChoiceOff &&
        report_last_ratio > 0 && report_last_ratio < options.stop_below_ratio)
      break;
    const uint64_t end = records[p.measured].offset + records[p.measured].size;
    auto applied = decoder.feed(stream.subspan(fed, end - fed));
    if (!applied) return tl::unexpected(applied.error());
    fed = end;
    const Mesh& prefix = decoder.mesh();
    AsaGuidanceReport::Group row;
    row.first_record = p.first;
    row.measured_record = p.measured;
    row.ratio = ratio_of(p.measured);
    const double plain = measure->relative_rms(prefix);
    row.rms.push_back(plain);
    double best_rms = plain * (1 - options.margin);
    uint8_t choice = kAsaChoiceOff;
    for (size_t k = 0; k < candidate_options.size(); ++k) {
      if (auto s = subdivide_into(prefix, candidate_options[k], workspace, out); !s)
        return tl::unexpected(s.error());
      const double rms =
          out.mesh.face_count() == prefix.face_count() ? plain : measure->relative_rms(out.mesh);
      row.rms.push_back(rms);
      if (rms < best_rms) {
        best_rms = rms;
        choice = options.candidates[k];
      }
    }
    row.choice = choice;
    report_last_ratio = row.ratio;
    if (guidance.groups.empty() || guidance.groups.back().choice != choice)
      guidance.groups.push_back({p.first, choice});
    if (report) report->groups.push_back(std::move(row));
  }
  // Nothing is missing from the complete stream: show it as decoded.
  if (guidance.groups.empty())
    guidance.groups.push_back({0, kAsaChoiceOff});
  else if (guidance.groups.back().choice != kAsaChoiceOff)
    guidance.groups.push_back({n - 1, kAsaChoiceOff});
  if (report)
    report->seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return guidance;
}

Result<std::vector<uint8_t>> with_asa_guidance(std::span<const uint8_t> stream,
                                               const AsaGuidance& guidance) {
  auto index = read_stream_index(stream);
  if (!index) return tl::unexpected(index.error());
  StreamHeader header = index->header;
  if (header.extra.size() < kExtensionsAt)
    return make_error(ErrorCode::kInvalidArgument,
                      "ASA guidance: the stream's header has no refinement format bytes");
  auto span = find_block(header.extra);
  if (!span) return tl::unexpected(span.error());
  if (*span)
    header.extra.erase(header.extra.begin() + std::ptrdiff_t((*span)->begin),
                       header.extra.begin() + std::ptrdiff_t((*span)->end));
  append_asa_guidance(header.extra, guidance);
  const std::vector<uint8_t> head = encode_stream_header(header);
  const uint32_t old_size = get_u32(stream.data() + 8);
  std::vector<uint8_t> out(stream.begin(), stream.begin() + 8);  // magic, version, flags
  put_u32(out, static_cast<uint32_t>(head.size()));
  out.insert(out.end(), head.begin(), head.end());
  put_u32(out, crc32(0, head.data(), head.size()));
  out.insert(out.end(), stream.begin() + 12 + old_size + 4, stream.end());
  return out;
}

}  // namespace meshstream
