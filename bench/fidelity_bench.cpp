// fidelity_bench: does ASA make a stream prefix look and measure closer to
// the real model? (issue 20, point 1; the baseline for encoder-guided
// post-processing.)
//
// For every real mesh (bench/real_mesh_list.h; bunny.stl is left out, it is
// bun_zipper.ply again), our own stream is cut at compression ratios 40, 20,
// 10 and 5 (ratio = full stream bytes / prefix bytes, prefix_for_budget) and
// the prefix decoded with the library decoder. Each prefix is shown plain
// and post-processed by the default ASA and a few variants, and judged by
//  - picture PSNR: the off-screen snapshot the client's --snapshot uses
//    (render_offscreen, 640x480, same shading for all) against the snapshot
//    of the complete decoded stream, from the same camera: the default
//    fit-to-model view of the complete mesh and three more around it
//    (the other two thirds of the circle, and from above); the mean over
//    the views, in dB;
//  - RMS and Hausdorff distance to the original (common/metrics), relative
//    to its bounding-box diagonal.
// Gain = variant's PSNR - plain prefix's PSNR (positive: ASA helps).
//
// Writes bench/report/fidelity.md (or DIR/fidelity.md with --report-dir DIR).
// Usage: fidelity_bench [--report-dir DIR] [--quick] [--meshes a.off,b.ply]
//                       [--margin M] [--groups-per-octave G] [--guidance-samples N]
//                       [--guidance-only] [--few-variants] [--no-approximate]
//                       [--shading-margin M] [--ratios 20,10] [--spikes]
//                       [--middle-only]
//   --margin, --groups-per-octave: the guidance's AsaGuidanceOptions (the
//   encoder's defaults otherwise), to measure what they change.
//   --guidance-only: no pictures, only the guidance's choices and its cost.
//   --few-variants: plain, auto, the old default and the approximating
//   option only (half the pictures).
//   --no-approximate: the guidance without its approximating candidate.
//   --shading-margin M: the guidance's shading margin (< 0: distance alone).
//   --quick: fandisk, casting and hemisphere only (about 40 s of CPU).
//   --ratios: only these compression ratios.
//   --middle-only: the guidance measures each group at its middle prefix
//   only (AsaGuidanceOptions::check_finest_end = false).
//   --spikes: the variants of the offset bound (issue 20 point 3): auto and
//   the old default with and without it, crease detection at t 0.85.
// MESHSTREAM_FIDELITY_PNG_DIR=DIR also writes the default-view pictures there.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "bench/real_mesh_list.h"
#include "client/viewer/offscreen.h"
#include "common/asa/approximate.h"
#include "common/asa/subdivide.h"
#include "common/codec/asa_guidance.h"
#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "common/mesh/import.h"
#include "common/metrics/distance.h"
#include "tests/test_meshes.h"

namespace meshstream::bench {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 640;
constexpr int kHeight = 480;
std::vector<int> kRatios = {40, 20, 10, 5};  // --ratios replaces them
constexpr double kPsnrCap = 99.0;            // identical pictures

struct View {
  float yaw, pitch;
};
// The client's default snapshot direction first (OffscreenRequest's), then
// the rest of the circle and a view from above.
const std::vector<View> kViews = {{0.6f, 0.35f}, {2.69f, 0.35f}, {-1.49f, 0.35f}, {0.6f, 1.1f}};

struct Variant {
  std::string label;
  bool asa = true;
  AsaOptions options;
  bool guided = false;       // the stream's ASA guidance (asa_guidance.h), `--asa auto`
  bool approximate = false;  // relax_toward_smooth, then ASA (`--approximate`)
  bool bound = true;         // the offset bound (AsaOptions::bound_offsets, issue 20 point 3)
};

// --spikes: the offset bound on and off for the guided and the old default
// settings, and crease detection at the old default's t (issue 20 point 3).
// The first three keep the roles the report gives them (plain, auto, old).
std::vector<Variant> spike_variants() {
  std::vector<Variant> v;
  v.push_back({"no ASA", false, {}});
  v.push_back({"auto (encoder-guided)", true, {}, true});
  v.push_back({"old default (L1, t 0.85)", true, {}});
  Variant unbounded{"auto, without the offset bound", true, {}, true};
  unbounded.bound = false;
  v.push_back(unbounded);
  unbounded = {"old default, without the offset bound", true, {}};
  unbounded.bound = false;
  v.push_back(unbounded);
  AsaOptions o;
  o.crease_degrees = 45;
  v.push_back({"crease 45 (t 0.85)", true, o});
  o.crease_degrees = 60;
  v.push_back({"crease 60 (t 0.85)", true, o});
  return v;
}

// `few`: only what the targets need (plain, auto, old default) and the
// approximating option: half the pictures.
std::vector<Variant> variants(bool few) {
  std::vector<Variant> v;
  v.push_back({"no ASA", false, {}});
  v.push_back({"auto (encoder-guided)", true, {}, true});
  v.push_back({"old default (L1, t 0.85)", true, {}});
  AsaOptions o;
  o.flatness = 0.95f;
  o.crease_degrees = 45;
  v.push_back({"approximate (L1 t0.95 crease45, relaxed)", true, o, false, true});
  if (few) return v;
  o = {};
  o.levels = 2;
  v.push_back({"levels 2", true, o});
  o = {};
  o.flatness = 0.95f;
  v.push_back({"t 0.95", true, o});
  o = {};
  o.crease_degrees = 30;
  v.push_back({"crease 30 (refused by the programs: below acos(0.85))", true, o});
  o = {};
  o.crease_degrees = 45;
  v.push_back({"crease 45", true, o});
  o = {};
  o.rule = ButterflyRule::kProjection;
  v.push_back({"rule projection", true, o});
  return v;
}

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

double psnr_rgb(const client::RgbaImage& a, const client::RgbaImage& b) {
  if (a.rgba.size() != b.rgba.size() || a.rgba.empty()) return 0;
  double sum = 0;
  for (size_t i = 0; i < a.rgba.size(); i += 4) {
    for (size_t k = 0; k < 3; ++k) {
      const double d = double(a.rgba[i + k]) - double(b.rgba[i + k]);
      sum += d * d;
    }
  }
  const double mse = sum / (3.0 * double(a.rgba.size() / 4));
  if (mse == 0) return kPsnrCap;
  return std::min(kPsnrCap, 10.0 * std::log10(255.0 * 255.0 / mse));
}

Result<std::vector<client::RgbaImage>> pictures(const Mesh& mesh, const Mesh& frame_on) {
  std::vector<client::RgbaImage> out;
  for (const View& view : kViews) {
    client::OffscreenRequest r;
    r.width = kWidth;
    r.height = kHeight;
    r.yaw = view.yaw;
    r.pitch = view.pitch;
    r.frame_on = &frame_on;
    auto image = client::render_offscreen(mesh, r);
    if (!image) return tl::unexpected(image.error());
    out.push_back(std::move(*image));
  }
  return out;
}

struct Measure {
  bool ok = false;
  std::string error;
  uint32_t faces = 0;
  double psnr = 0;  // mean over the views
  double worst_view_psnr = 0;
  std::vector<double> view_psnr;  // per view of kViews
  double rms = 0, hausdorff = 0;  // relative to the original's diagonal
};

struct Row {  // one mesh at one ratio
  std::string mesh;
  int ratio = 0;
  uint64_t prefix_bytes = 0;
  uint32_t prefix_faces = 0;
  std::string choice;  // what the guidance chose for this prefix
  std::vector<Measure> by_variant;
};

struct EncodeCost {  // one mesh's encode with and without guidance
  std::string mesh;
  double seconds_plain = 0, seconds_guided = 0;
  uint64_t bytes_plain = 0, bytes_guided = 0;
  size_t groups = 0;
  std::string choices;
};

struct Stats {
  double mean = 0, worst = 0;
  size_t n = 0;
};
Stats stats(const std::vector<double>& v) {
  Stats s;
  if (v.empty()) return s;
  s.n = v.size();
  s.worst = *std::min_element(v.begin(), v.end());
  for (double x : v) s.mean += x;
  s.mean /= double(v.size());
  return s;
}

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace
}  // namespace meshstream::bench

int main(int argc, char** argv) {
  using namespace meshstream;
  using namespace meshstream::bench;
  std::string report_dir;
  bool quick = false;
  std::vector<std::string> names;
  AsaGuidanceOptions guidance_options;  // the encoder's defaults unless asked otherwise
  guidance_options.threads = EncodeOptions{}.threads;  // as encode_hcs passes them
  bool guidance_only = false;  // no pictures: the guidance's choices and cost
  bool spikes = false;         // the offset bound's variants (spike_variants)
  bool few_variants = false;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--report-dir" && i + 1 < argc) {
      report_dir = argv[++i];
    } else if (a == "--margin" && i + 1 < argc) {
      guidance_options.margin = std::atof(argv[++i]);
    } else if (a == "--groups-per-octave" && i + 1 < argc) {
      guidance_options.groups_per_octave = std::atoi(argv[++i]);
    } else if (a == "--guidance-samples" && i + 1 < argc) {
      guidance_options.samples = uint32_t(std::atoi(argv[++i]));
    } else if (a == "--probe-faces" && i + 1 < argc) {
      guidance_options.probe_faces = uint32_t(std::atoi(argv[++i]));
    } else if (a == "--candidates" && i + 1 < argc) {
      guidance_options.candidates.clear();
      for (const std::string& c : split_commas(argv[++i]))
        guidance_options.candidates.push_back(uint8_t(std::stoi(c, nullptr, 0)));
    } else if (a == "--shading-margin" && i + 1 < argc) {
      guidance_options.shading_margin = std::atof(argv[++i]);
    } else if (a == "--few-variants") {
      few_variants = true;
    } else if (a == "--no-approximate") {
      guidance_options.approximate = false;
    } else if (a == "--guidance-only") {
      guidance_only = true;
    } else if (a == "--quick") {
      quick = true;
    } else if (a == "--spikes") {
      spikes = true;
    } else if (a == "--middle-only") {
      guidance_options.check_finest_end = false;
    } else if (a == "--ratios" && i + 1 < argc) {
      kRatios.clear();
      for (const std::string& r : split_commas(argv[++i])) kRatios.push_back(std::stoi(r));
    } else if (a == "--meshes" && i + 1 < argc) {
      names = split_commas(argv[++i]);
    } else if (a == "--help" || a == "-h") {
      std::printf(
          "usage: fidelity_bench [--report-dir DIR] [--quick] [--meshes a.off,b.ply] "
          "[--margin M] [--groups-per-octave G] [--guidance-samples N] [--guidance-only] "
          "[--few-variants] [--no-approximate] [--shading-margin M] [--ratios 20,10] "
          "[--spikes] [--middle-only]\n");
      return 0;
    } else {
      std::fprintf(stderr, "fidelity_bench: unknown argument %s\n", a.c_str());
      return 2;
    }
  }
  if (report_dir.empty()) {
#ifdef MESHSTREAM_SOURCE_DIR
    report_dir = std::string(MESHSTREAM_SOURCE_DIR) + "/bench/report";
#else
    report_dir = "bench/report";
#endif
  }
  if (testing::test_mesh_dir().empty()) {
    std::fprintf(stderr, "fidelity_bench: real meshes not found (set MESHSTREAM_TEST_MESHES)\n");
    return 1;
  }
  if (names.empty()) {
    if (quick) {
      names = {"fandisk.off", "casting.off", "hemisphere.off"};
    } else {
      for (const std::string& n : kRealMeshes)
        if (n != "bunny.stl") names.push_back(n);
    }
  }

  const double t_start = now_s();
  const std::vector<Variant> vars = spikes ? spike_variants() : variants(few_variants);
  std::vector<Row> rows;
  std::vector<EncodeCost> costs;
  std::vector<std::string> skipped;
  DistanceOptions dopt;
  dopt.samples = 50000;
  for (const std::string& name : names) {
    auto imported = import_mesh(testing::test_mesh(name));
    if (!imported) {
      skipped.push_back(name + ": " + imported.error().message);
      std::fprintf(stderr, "fidelity_bench: skip %s\n", skipped.back().c_str());
      continue;
    }
    const Mesh& original = imported->mesh;
    EncodeOptions unguided;
    unguided.asa_guidance = false;
    const double t_plain = now_s();
    const std::clock_t cpu_plain = std::clock();
    auto plain_stream = encode_hcs(original, unguided);
    const double t_guided = now_s();
    const std::clock_t cpu_guided = std::clock();
    // What encode_hcs does by default (encoder.cpp), here with the bench's
    // options: measure the guidance on the finished stream, then write it.
    AsaGuidanceReport guidance_report;
    auto measured = plain_stream ? measure_asa_guidance(original, *plain_stream, guidance_options,
                                                        &guidance_report)
                                 : tl::unexpected(plain_stream.error());
    auto stream =
        measured ? with_asa_guidance(*plain_stream, *measured) : tl::unexpected(measured.error());
    const double t_done = now_s();
    const std::clock_t cpu_done = std::clock();
    for (const AsaGuidanceReport::Group& g : guidance_report.groups) {
      std::printf(
          "%s guidance group from record %u (measured at ratio %.1f, %u faces, %.2f s): %s; RMS "
          "/ off:",
          name.c_str(), g.first_record, g.ratio, g.prefix_faces, g.seconds,
          asa_choice_label(g.choice).c_str());
      for (size_t k = 1; k < g.rms.size(); ++k)
        std::printf(" %s %.3f n %.3f;",
                    asa_choice_label(guidance_options.candidates[k - 1]).c_str(),
                    g.rms[k] / g.rms[0], g.normal[k] / g.normal[0]);
      if (g.approximate_rms > 0)
        std::printf(" approximate %.3f n %.3f;", g.approximate_rms / g.rms[0],
                    g.approximate_normal / g.normal[0]);
      if (g.finest_ratio > 0)
        std::printf(" at the finest prefix (ratio %.1f): %.3f n %.3f;", g.finest_ratio,
                    g.finest_rms_ratio, g.finest_normal_ratio);
      std::printf("\n");
    }
    auto index = stream ? read_stream_index(*stream) : tl::unexpected(stream.error());
    auto full = stream ? decode_hcs(*stream) : tl::unexpected(stream.error());
    auto prepared_original = PreparedSurface::prepare(original, dopt);
    if (!stream || !index || !full || !prepared_original) {
      skipped.push_back(name + ": does not encode/decode");
      continue;
    }
    auto guidance = read_asa_guidance(index->header, uint32_t(index->records.size()));
    if (!guidance || !*guidance || !plain_stream) {
      std::fprintf(stderr, "fidelity_bench: %s: the stream has no readable ASA guidance\n",
                   name.c_str());
      return 1;
    }
    {
      EncodeCost c;
      c.mesh = name;
      c.seconds_plain = t_guided - t_plain;
      c.seconds_guided = t_done - t_plain;  // the encode and its guidance
      c.bytes_plain = plain_stream->size();
      c.bytes_guided = stream->size();
      c.groups = (*guidance)->groups.size();
      for (const AsaGuidanceGroup& g : (*guidance)->groups) {
        if (!c.choices.empty()) c.choices += ", ";
        c.choices += std::to_string(g.first_record) + ": " + asa_choice_label(g.choice);
      }
      costs.push_back(c);
      std::printf("%s: encode %.2f s, with guidance %.2f s (CPU %.2f s, guidance %.2f s); %s\n",
                  name.c_str(), c.seconds_plain, c.seconds_guided,
                  double(cpu_guided - cpu_plain) / CLOCKS_PER_SEC,
                  double(cpu_done - cpu_guided) / CLOCKS_PER_SEC, c.choices.c_str());
      std::fflush(stdout);
    }
    if (guidance_only) continue;
    auto reference = pictures(*full, *full);
    if (!reference) {
      std::fprintf(stderr, "fidelity_bench: %s: %s\n", name.c_str(),
                   reference.error().message.c_str());
      return 1;
    }
    for (int ratio : kRatios) {
      Row row;
      row.mesh = name;
      row.ratio = ratio;
      row.prefix_bytes = prefix_for_budget(*index, DecodeBudget::ratio(ratio));
      auto prefix = decode_hcs(std::span<const uint8_t>(stream->data(), row.prefix_bytes));
      if (!prefix) {
        skipped.push_back(name + " ratio " + std::to_string(ratio) + ": " + prefix.error().message);
        continue;
      }
      row.prefix_faces = prefix->face_count();
      for (const Variant& v : vars) {
        Measure m;
        Mesh shown;
        // The choice byte shown: the guidance's, or the variant's own.
        uint8_t choice = kAsaChoiceOff;
        if (v.guided) {
          uint32_t records = 0;
          while (records < index->records.size() &&
                 index->records[records].offset + index->records[records].size <= row.prefix_bytes)
            ++records;
          choice = (*guidance)->choice_for(records);
          row.choice = asa_choice_label(choice);
        }
        const bool asa = v.guided ? choice != kAsaChoiceOff : v.asa;
        if (asa) {
          Result<Mesh> r = tl::unexpected(Error{ErrorCode::kInvalidArgument, "no choice byte"});
          if (v.guided && v.bound) {
            r = apply_asa_choice(*prefix, choice);
          } else if (v.guided) {  // the guidance's choice with the plain rules (--spikes)
            auto o = asa_choice_options(choice);
            Mesh input = *prefix;
            if (o && *o && asa_choice_approximates(choice))
              (void)relax_toward_smooth(input, asa_choice_relax(**o));
            if (!o || !*o) {
              r = tl::unexpected(o ? Error{ErrorCode::kInvalidArgument, "no ASA"} : o.error());
            } else {
              AsaOptions plain = **o;
              plain.bound_offsets = false;
              if (auto s = subdivide(input, plain))
                r = std::move(s->mesh);
              else
                r = tl::unexpected(s.error());
            }
          } else if (v.approximate) {
            r = apply_asa_choice(*prefix, *approximating_choice(*asa_choice_of(v.options)));
          } else if (auto s = subdivide(*prefix, [&] {
                       AsaOptions o = v.options;
                       o.bound_offsets = v.bound;
                       return o;
                     }())) {
            r = std::move(s->mesh);
          } else {
            r = tl::unexpected(s.error());
          }
          if (!r) {
            m.error = r.error().message;
            row.by_variant.push_back(m);
            continue;
          }
          if (r->face_count() == prefix->face_count() && !row.by_variant.empty() &&
              !asa_choice_approximates(choice) && !v.approximate) {
            // Nothing split: the output is the prefix itself (old vertices and
            // face order are kept), so it measures as the plain prefix.
            row.by_variant.push_back(row.by_variant.front());
            continue;
          }
          shown = std::move(*r);
        } else {
          shown = *prefix;
        }
        auto seen = pictures(shown, *full);
        if (seen && std::getenv("MESHSTREAM_FIDELITY_PNG_DIR")) {  // to look at them
          const std::string stem = std::string(std::getenv("MESHSTREAM_FIDELITY_PNG_DIR")) + "/" +
                                   name + "." + std::to_string(ratio) + "." +
                                   std::to_string(&v - vars.data());
          (void)client::write_png(stem + ".png", seen->front());
          (void)client::write_png(stem + ".full.png", reference->front());
        }
        auto prepared = PreparedSurface::prepare(shown, dopt);
        if (!seen || !prepared) {
          m.error = !seen ? seen.error().message : prepared.error().message;
          row.by_variant.push_back(m);
          continue;
        }
        m.ok = true;
        m.faces = shown.face_count();
        m.worst_view_psnr = kPsnrCap;
        for (size_t k = 0; k < kViews.size(); ++k) {
          const double p = psnr_rgb((*seen)[k], (*reference)[k]);
          m.psnr += p / double(kViews.size());
          m.worst_view_psnr = std::min(m.worst_view_psnr, p);
          m.view_psnr.push_back(p);
        }
        const SurfaceDistance d = surface_distance(*prepared_original, *prepared);
        m.rms = d.relative_rms();
        m.hausdorff = d.relative_hausdorff();
        row.by_variant.push_back(m);
      }
      std::printf("%s ratio %d (%u faces):", name.c_str(), ratio, row.prefix_faces);
      for (size_t k = 0; k < vars.size(); ++k)
        std::printf(" %s %.2f dB;", vars[k].label.c_str(), row.by_variant[k].psnr);
      std::printf("\n");
      std::fflush(stdout);
      rows.push_back(std::move(row));
    }
  }
  const double seconds = now_s() - t_start;

  std::ostringstream md;
  md << "## Fidelity: does ASA bring a prefix closer to the model? (fidelity_bench)\n\n"
     << "Each real mesh is streamed (our encoder, defaults) and cut at compression ratios 40, 20, "
        "10 and 5 (full stream bytes / prefix bytes, a record boundary); the prefix is decoded "
        "with the library decoder and shown plain, with the ASA setting the encoder's guidance "
        "chose for it (`--asa auto`, "
        "asa_guidance.h), with the old fixed default ASA (1 level, t = 0.85, no creases, Zorin "
        "rule) and with variants that change one setting of it. **PSNR**: the "
        "client's off-screen snapshot renderer at "
     << kWidth << "x" << kHeight
     << ", the same camera for every picture of a mesh (framed on the complete decoded "
        "stream), against the complete stream's picture; mean over "
     << kViews.size()
     << " views (the default fit-to-model direction, two more around the model, one from "
        "above). **RMS / Hausdorff**: symmetric surface distance to the original (50 000 "
        "samples a side), relative to its bounding-box diagonal. **Gain**: variant PSNR minus "
        "plain prefix PSNR, in dB. Shading is the renderer's default for every picture (so "
        "only the geometry differs). "
     << rows.size() << " mesh/ratio pairs, " << fmt("%.0f", seconds) << " s.\n\n";
  if (!skipped.empty()) {
    md << "Skipped:";
    for (const std::string& s : skipped) md << " " << s << ";";
    md << "\n\n";
  }

  md << "### Per mesh: plain prefix, the encoder-guided choice (`--asa auto`) and the old fixed "
        "default\n\n"
     << "| mesh | ratio | prefix faces | guided choice | PSNR plain | auto | old default | gain "
        "auto | gain old | worst-view gain auto | RMS plain | RMS auto | RMS old | Hausdorff "
        "plain | Hausdorff auto |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Row& r : rows) {
    const Measure& p = r.by_variant[0];
    const Measure& a = r.by_variant[1];
    const Measure& o = r.by_variant[2];
    if (!p.ok || !a.ok || !o.ok) {
      md << "| " << r.mesh << " | " << r.ratio << " | n/a: " << p.error << a.error << o.error
         << " |\n";
      continue;
    }
    md << "| " << r.mesh << " | " << r.ratio << " | " << r.prefix_faces << " | " << r.choice
       << " | " << fmt("%.2f", p.psnr) << " | " << fmt("%.2f", a.psnr) << " | "
       << fmt("%.2f", o.psnr) << " | " << fmt("%+.2f", a.psnr - p.psnr) << " | "
       << fmt("%+.2f", o.psnr - p.psnr) << " | "
       << fmt("%+.2f", a.worst_view_psnr - p.worst_view_psnr) << " | " << fmt("%.2e", p.rms)
       << " | " << fmt("%.2e", a.rms) << " | " << fmt("%.2e", o.rms) << " | "
       << fmt("%.2e", p.hausdorff) << " | " << fmt("%.2e", a.hausdorff) << " |\n";
  }

  // The targets of issue 20 for the default (`--asa auto`).
  {
    double worst_2010 = 1e9, mean_all = 0, worst_rms = 0, worst_view_2010 = 1e9;
    std::string worst_at, worst_view_at;
    size_t n = 0;
    for (const Row& r : rows) {
      const Measure& p = r.by_variant[0];
      const Measure& a = r.by_variant[1];
      if (!p.ok || !a.ok) continue;
      const double gain = a.psnr - p.psnr;
      mean_all += gain;
      ++n;
      if ((r.ratio == 20 || r.ratio == 10) && gain < worst_2010) {
        worst_2010 = gain;
        worst_at = r.mesh + " at ratio " + std::to_string(r.ratio);
      }
      // The issue's own measure is one picture (the default view): every
      // view must hold, not only their mean.
      for (size_t k = 0;
           (r.ratio == 20 || r.ratio == 10) && k < p.view_psnr.size() && k < a.view_psnr.size();
           ++k) {
        const double g = a.view_psnr[k] - p.view_psnr[k];
        if (g < worst_view_2010) {
          worst_view_2010 = g;
          worst_view_at = r.mesh + " at ratio " + std::to_string(r.ratio) + ", view " +
                          std::to_string(k + 1) + (k == 0 ? " (the default)" : "");
        }
      }
      if (p.rms > 0) worst_rms = std::max(worst_rms, a.rms / p.rms);
    }
    if (n > 0) mean_all /= double(n);
    double guidance_share = 0, time_ratio_worst = 0, seconds_plain = 0, seconds_guided = 0;
    for (const EncodeCost& c : costs) {
      guidance_share = std::max(guidance_share, double(c.bytes_guided - c.bytes_plain) /
                                                    double(std::max<uint64_t>(c.bytes_plain, 1)));
      time_ratio_worst = std::max(time_ratio_worst, c.seconds_guided / c.seconds_plain);
      seconds_plain += c.seconds_plain;
      seconds_guided += c.seconds_guided;
    }
    md << "\n### Targets (the default, `--asa auto`, against the plain prefix)\n\n"
       << "| target | measured | |\n|---|---|---|\n"
       << "| never more than 0.1 dB below the plain prefix at ratios 20 and 10 | worst "
       << fmt("%+.2f", worst_2010) << " dB (" << worst_at << ") | "
       << (worst_2010 >= -0.1 ? "met" : "not met") << " |\n"
       << "| the same, in every single view (not only their mean) | worst "
       << fmt("%+.2f", worst_view_2010) << " dB (" << worst_view_at << ") | "
       << (worst_view_2010 >= -0.1 ? "met" : "not met") << " |\n"
       << "| mean gain at least 0.5 dB (all ratios) | " << fmt("%+.2f", mean_all) << " dB | "
       << (mean_all >= 0.5 ? "met" : "not met") << " |\n"
       << "| RMS never more than 2 % above the plain prefix's | worst " << fmt("%.3f", worst_rms)
       << "x | " << (worst_rms <= 1.02 ? "met" : "not met") << " |\n"
       << "| guidance at most 0.5 % of the stream | worst " << fmt("%.3f", 100 * guidance_share)
       << " % | " << (guidance_share <= 0.005 ? "met" : "not met") << " |\n"
       << "| encode time (not a target: its cost) | " << fmt("%.1f", seconds_plain) << " s -> "
       << fmt("%.1f", seconds_guided) << " s over the meshes, worst mesh "
       << fmt("%.2f", time_ratio_worst) << "x | |\n";
    md << "\n### The guidance per stream (encode time without / with it, bytes)\n\n"
       << "| mesh | encode s | guided encode s | stream bytes | guided bytes | share | groups | "
          "choices (first record: setting) |\n|---|---|---|---|---|---|---|---|\n";
    for (const EncodeCost& c : costs) {
      md << "| " << c.mesh << " | " << fmt("%.2f", c.seconds_plain) << " | "
         << fmt("%.2f", c.seconds_guided) << " | " << c.bytes_plain << " | " << c.bytes_guided
         << " | "
         << fmt("%.3f %%", 100.0 * double(c.bytes_guided - c.bytes_plain) / double(c.bytes_plain))
         << " | " << c.groups << " | " << c.choices << " |\n";
    }
  }

  // Gains of every variant, per ratio and over all pairs.
  md << "\n### Every variant: PSNR gain over the plain prefix (mean / worst, dB) and RMS\n\n"
     << "| variant |";
  for (int ratio : kRatios) md << " ratio " << ratio << " |";
  md << " all | RMS / plain (mean, worst) | meshes refused |\n|---|";
  for (size_t k = 0; k <= std::size(kRatios) + 2; ++k) md << "---|";
  md << "\n";
  struct Summary {
    std::string label;
    Stats all;
    bool changes_something = false;  // on at least one mesh and ratio
    bool guided = false;             // not a fixed setting
  };
  std::vector<Summary> summaries;
  for (size_t v = 1; v < vars.size(); ++v) {
    md << "| " << vars[v].label << " |";
    std::vector<double> all, rms_ratio;
    size_t refused = 0;
    bool changes = false;
    for (const Row& r : rows)
      changes |= r.by_variant[v].ok && r.by_variant[v].faces != r.by_variant[0].faces;
    for (int ratio : kRatios) {
      std::vector<double> g;
      for (const Row& r : rows) {
        if (r.ratio != ratio || !r.by_variant[0].ok) continue;
        if (!r.by_variant[v].ok) {
          ++refused;
          continue;
        }
        g.push_back(r.by_variant[v].psnr - r.by_variant[0].psnr);
        if (r.by_variant[0].rms > 0) rms_ratio.push_back(r.by_variant[v].rms / r.by_variant[0].rms);
      }
      all.insert(all.end(), g.begin(), g.end());
      const Stats s = stats(g);
      md << " " << fmt("%+.2f", s.mean) << " / " << fmt("%+.2f", s.worst) << " |";
    }
    const Stats s = stats(all);
    double rms_mean = 0, rms_worst = 0;
    for (double x : rms_ratio) {
      rms_mean += x / double(rms_ratio.size());
      rms_worst = std::max(rms_worst, x);
    }
    md << " **" << fmt("%+.2f", s.mean) << " / " << fmt("%+.2f", s.worst) << "** | "
       << fmt("%.2f", rms_mean) << "x, " << fmt("%.2f", rms_worst) << "x | " << refused << " |\n";
    summaries.push_back({vars[v].label, s, changes, vars[v].guided});
  }

  // The best fixed default: the issue's target is "never more than 0.1 dB
  // below the plain prefix", so a variant qualifies only with a worst gain
  // >= -0.1 dB; among those the best mean wins, and no ASA (gain 0) is the
  // answer when none qualifies.
  const Summary* best_mean = nullptr;
  const Summary* best_safe = nullptr;
  for (const Summary& s : summaries) {
    if (s.all.n == 0 || !s.changes_something || s.guided) continue;  // no ASA in disguise
    if (!best_mean || s.all.mean > best_mean->all.mean) best_mean = &s;
    if (s.all.worst >= -0.1 && s.all.mean > 0 && (!best_safe || s.all.mean > best_safe->all.mean))
      best_safe = &s;
  }
  md << "\n";
  for (const Summary& s : summaries)
    if (!s.changes_something)
      md << "*" << s.label << "* changes no prefix of these meshes: here it is no ASA, "
         << "and is left out of the choice below.\n\n";
  if (best_mean) {
    md << "Fixed settings (the guided choice aside): highest mean gain: **" << best_mean->label
       << "** (" << fmt("%+.2f", best_mean->all.mean) << " dB mean, "
       << fmt("%+.2f", best_mean->all.worst) << " dB worst over " << best_mean->all.n
       << " mesh/ratio pairs). ";
  }
  if (best_safe) {
    md << "Best fixed default that helps on average and is never more than 0.1 dB worse than "
          "the plain prefix: **"
       << best_safe->label << "** (" << fmt("%+.2f", best_safe->all.mean) << " dB mean).\n";
  } else {
    md << "No fixed variant both helps on average and stays within 0.1 dB of the plain prefix "
          "on every mesh and ratio, so "
          "judged on all meshes the best fixed default is **no ASA**; a post-processing that "
          "helps on average needs a per-stream (or per-record) choice, which is what the "
          "encoder-guided post-processing of issue 20 is for.\n";
  }

  fs::create_directories(report_dir);
  std::ofstream(report_dir + "/fidelity.md") << md.str();
  std::printf("wrote %s/fidelity.md (%.0f s)\n", report_dir.c_str(), seconds);
  return 0;
}
