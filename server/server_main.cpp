// meshstream-server: parse options -> load the catalog -> listen -> serve
// until SIGINT/SIGTERM -> exit 0.
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <cstdio>
#include <iostream>

#include "server/catalog.h"
#include "server/server.h"
#include "server/server_options.h"

using namespace meshstream::server;

namespace {

Catalog load_catalog(const ServerOptions& options) {
  std::vector<std::unique_ptr<CatalogSource>> sources;
  if (!options.models_dir.empty()) {
    sources.push_back(hcs_folder_source(options.models_dir));
    sources.push_back(mesh_folder_source({options.models_dir, options.cache_dir, 0}));
  }
  if (options.demo) sources.push_back(demo_source(options.cache_dir));
  Catalog catalog;
  for (auto& source : sources) {
    source->load(catalog, [](const std::string& line) { spdlog::info("catalog: {}", line); });
  }
  return catalog;
}

}  // namespace

int main(int argc, char** argv) {
  ParsedOptions parsed = parse_server_options(argc, argv);
  if (const int* exit_code = std::get_if<int>(&parsed)) return *exit_code;
  const ServerOptions& options = std::get<ServerOptions>(parsed);

  // Logs go to stderr; stdout carries only the "listening on" line.
  spdlog::set_default_logger(spdlog::stderr_color_mt("meshstream-server"));
  spdlog::set_level(spdlog::level::from_str(options.log_level));
  spdlog::set_pattern("%Y-%m-%dT%H:%M:%S.%e %^%l%$ %v");

  const Catalog catalog = load_catalog(options);
  if (catalog.size() == 0) spdlog::warn("catalog is empty: no model to serve");
  for (const CatalogModel* model : catalog.models()) {
    spdlog::info("serving {} ({}, {} vertices, {} bytes, {} records)", model->name, model->source,
                 model->index.header.vertex_count, model->index.total_bytes(),
                 model->index.records.size());
    if (model->compact.coded.empty()) {
      spdlog::warn(
          "{}: its record index cannot be coded compactly ({}); its headers carry the "
          "arrays",
          model->name, model->compact.refused);
    }
  }

  Server server(options, catalog);
  if (auto status = server.listen(); !status) {
    std::cerr << "meshstream-server: " << status.error().message << "\n";
    return 1;
  }
  const auto endpoint = server.local_endpoint();
  std::printf("listening on %s:%u\n", endpoint.address().to_string().c_str(),
              unsigned(endpoint.port()));
  std::fflush(stdout);
  server.run();
  return 0;
}
