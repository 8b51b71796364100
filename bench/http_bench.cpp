// http_bench: the HTTP stream path against the TCP path, on loopback.
//
// The same .hcs files served by the real meshstream-server (TCP, the
// meshstream protocol) and by a real nginx (docs/nginx.conf, HTTP/1.1 range
// requests), streamed by the real meshstream-client --json: time from the
// client's start to the first displayed mesh and to the end, median of
// interleaved runs, side by side; the target is HTTP at most 1.5x TCP.
// Also the bytes per range request (--max-chunk-bytes over http://) on one
// model, no ASA, where the transport shows most.
//
// Writes bench/report/http.md (or DIR/http.md with --report-dir DIR).
// Usage: http_bench [--report-dir DIR] [--quick] [--runs N]
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/client/client_harness.h"
#include "tests/http/web_servers.h"
#include "tests/test_meshes.h"

using namespace meshstream;
using namespace meshstream::clienttest;

namespace {

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

struct Times {
  bool ok = false;
  std::string error;
  double first_ms = 0, end_ms = 0;
};

Times stream_once(const std::vector<std::string>& target, const std::vector<std::string>& extra,
                  const std::string& dir) {
  Times t;
  std::vector<std::string> argv{client_bin()};
  argv.insert(argv.end(), target.begin(), target.end());
  argv.insert(argv.end(), {"--json", "--quiet"});
  argv.insert(argv.end(), extra.begin(), extra.end());
  const std::string out = dir + "/client.out", err = dir + "/client.err";
  const int status = run(argv, out, err);
  const auto events = parse_events(read_text(out));
  if (status != 0 || events.empty() || events.back().value("event", "") != "done") {
    t.error = "exit " + std::to_string(status) + ": " + read_text(err);
    return t;
  }
  const auto refinements = of_kind(events, "refinement");
  if (refinements.empty()) {
    t.error = "no refinement event";
    return t;
  }
  t.first_ms = refinements.front()["elapsed_ms"];
  t.end_ms = events.back()["elapsed_ms"];
  t.ok = true;
  return t;
}

struct Model {
  std::string name, origin;
  uint64_t bytes = 0;
};

struct Side {
  std::vector<double> first, end;
  std::string error;
};

}  // namespace

int main(int argc, char** argv) {
  std::string report_dir = std::string(MESHSTREAM_SOURCE_DIR) + "/bench/report";
  bool quick = false;
  int runs = 9;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--report-dir" && i + 1 < argc) {
      report_dir = argv[++i];
    } else if (a == "--quick") {
      quick = true;
    } else if (a == "--runs" && i + 1 < argc) {
      runs = std::max(1, std::atoi(argv[++i]));
    } else if (a == "-h" || a == "--help") {
      std::printf("usage: http_bench [--report-dir DIR] [--quick] [--runs N]\n");
      return 0;
    } else {
      std::fprintf(stderr, "http_bench: unknown argument '%s'\n", argv[i]);
      return 2;
    }
  }
  if (quick) runs = std::min(runs, 3);
  TempDir dir;
  fs::create_directories(dir / "www/models");
  std::vector<Model> models;
  auto encode = [&](const std::string& input, const std::string& name, const std::string& origin) {
    const std::string hcs = dir / ("www/models/" + name + ".hcs");
    if (run({tool_bin(), "encode", input, "-o", hcs}, dir / "enc.out", dir / "enc.err") != 0) {
      std::fprintf(stderr, "http_bench: cannot encode %s: %s\n", input.c_str(),
                   read_text(dir / "enc.err").c_str());
      return;
    }
    models.push_back({name, origin, fs::file_size(hcs)});
  };
  if (run({tool_bin(), "generate", "demo", "--size", "200000", "-o", dir / "demo.ply"},
          dir / "gen.out", dir / "gen.err") == 0)
    encode(dir / "demo.ply", "demo", "procedural demo model (generate demo --size 200000)");
  const std::string meshes = meshstream::testing::test_mesh_dir();
  if (!meshes.empty()) {
    encode(meshes + "/bunny.off", "bunny", "bunny.off");
    if (!quick) encode(meshes + "/dragon_res2.ply", "dragon_res2", "dragon_res2.ply");
  }
  if (models.empty()) {
    std::fprintf(stderr, "http_bench: no model encoded\n");
    return 1;
  }

  Nginx nginx;
  if (const std::string why = nginx.start(dir / "www", dir / "nginx"); !why.empty()) {
    std::fprintf(stderr, "http_bench: %s\n", why.c_str());
    return 1;
  }
  Server server;
  if (!server.start({"--models", dir / "www/models", "--cache", dir / "cache"}, dir.path())) {
    std::fprintf(stderr, "http_bench: server did not start: %s\n", server.log().c_str());
    return 1;
  }
  const std::string base = "http://127.0.0.1:" + std::to_string(nginx.port()) + "/models/";
  const std::string load = read_text("/proc/loadavg").substr(0, 14);

  // One row: TCP and HTTP runs interleaved (after one warm-up of each), so
  // both see the same machine load.
  auto compare = [&](const Model& m, const std::vector<std::string>& extra, Side& tcp, Side& http) {
    const std::vector<std::string> tcp_target{server.address(), m.name};
    const std::vector<std::string> http_target{base + m.name + ".hcs"};
    stream_once(tcp_target, extra, dir.path());
    stream_once(http_target, extra, dir.path());
    for (int i = 0; i < runs; ++i) {
      for (auto [target, side] : {std::pair{&tcp_target, &tcp}, std::pair{&http_target, &http}}) {
        Times t = stream_once(*target, extra, dir.path());
        if (!t.ok) {
          side->error = t.error;
          continue;
        }
        side->first.push_back(t.first_ms);
        side->end.push_back(t.end_ms);
      }
    }
  };

  std::ostringstream md;
  md << "## HTTP range requests through nginx vs the TCP path (http_bench)\n\n"
     << "Loopback; the same `.hcs` files served by `meshstream-server` (TCP) and by nginx "
        "(`docs/nginx.conf`: HTTP/1.1 range requests, 64 KiB first, then whole records, 256 "
        "KiB a request by default, one kept-alive connection), streamed by the real "
        "`meshstream-client --json`. Times from the client's start to the first displayed "
        "mesh and to the `done` event; medians of "
     << runs
     << " runs of each, TCP and HTTP interleaved after one warm-up run of each. Load average "
        "when the run started: "
     << load << " (2 shared cores). Target: HTTP at most 1.5x TCP.\n\n"
     << "| model | stream bytes | client | first display ms TCP | HTTP | ratio | end ms TCP | "
        "HTTP | ratio | target |\n"
     << "|---|---|---|---|---|---|---|---|---|---|\n";
  bool all_met = true;
  std::vector<std::string> failures;
  for (const Model& m : models) {
    for (const auto& [label, extra] :
         {std::pair<std::string, std::vector<std::string>>{"default ASA", {}},
          {"--no-asa", {"--no-asa"}}}) {
      Side tcp, http;
      compare(m, extra, tcp, http);
      if (tcp.first.empty() || http.first.empty()) {
        failures.push_back(m.name + " " + label + ": " + tcp.error + http.error);
        all_met = false;
        continue;
      }
      const double f_tcp = median(tcp.first), f_http = median(http.first);
      const double e_tcp = median(tcp.end), e_http = median(http.end);
      const double rf = f_http / f_tcp, re = e_http / e_tcp;
      const bool met = rf <= 1.5 && re <= 1.5;
      all_met = all_met && met;
      md << "| " << m.name << " | " << m.bytes << " | " << label << " | " << fmt("%.1f", f_tcp)
         << " | " << fmt("%.1f", f_http) << " | " << fmt("%.2f", rf) << " | " << fmt("%.1f", e_tcp)
         << " | " << fmt("%.1f", e_http) << " | " << fmt("%.2f", re) << " | "
         << (met ? "met" : "not met") << " |\n";
      std::fflush(stdout);
      std::printf("%s %s: first %.1f / %.1f ms, end %.1f / %.1f ms\n", m.name.c_str(),
                  label.c_str(), f_tcp, f_http, e_tcp, e_http);
    }
  }
  md << "\nTarget (HTTP first display and end-to-end at most 1.5x TCP's, every row): **"
     << (all_met ? "met" : "not met") << "**.";
  for (const std::string& f : failures) md << " Failed: " << f << ".";
  md << "\n\n";

  // Bytes per range request, on the largest model, no ASA.
  const Model& big =
      *std::max_element(models.begin(), models.end(),
                        [](const Model& a, const Model& b) { return a.bytes < b.bytes; });
  md << "Bytes per range request (`--max-chunk-bytes` over `http://`), " << big.name << " ("
     << big.bytes << " bytes), `--no-asa`, medians of " << runs << " runs:\n\n"
     << "| bytes per request | requests | first display ms | end ms |\n|---|---|---|---|\n";
  for (uint64_t chunk : {uint64_t{16384}, uint64_t{65536}, uint64_t{262144}, uint64_t{1048576}}) {
    std::vector<double> first, end;
    const std::string before = nginx.access_log();
    const size_t requests_before = std::count(before.begin(), before.end(), '\n');
    for (int i = 0; i < runs; ++i) {
      Times t = stream_once({base + big.name + ".hcs"},
                            {"--no-asa", "--max-chunk-bytes", std::to_string(chunk)}, dir.path());
      if (!t.ok) continue;
      first.push_back(t.first_ms);
      end.push_back(t.end_ms);
    }
    const std::string after = nginx.access_log();
    const size_t requests = std::count(after.begin(), after.end(), '\n') - requests_before;
    md << "| " << chunk << " | " << fmt("%.0f", double(requests) / runs) << " | "
       << fmt("%.1f", median(first)) << " | " << fmt("%.1f", median(end)) << " |\n";
  }
  md << "\n";

  fs::create_directories(report_dir);
  std::ofstream(report_dir + "/http.md") << md.str();
  std::printf("%s", md.str().c_str());
  std::printf("wrote %s/http.md\n", report_dir.c_str());
  return 0;
}
