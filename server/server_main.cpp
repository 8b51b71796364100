// meshstream-server: parse options -> check the folders -> bind the address
// -> load the catalog (encoding what is not cached) -> announce the port ->
// serve until SIGINT/SIGTERM -> exit 0. Bad input (a folder that is not
// there, an address in use, nothing to serve) exits 1 with one line.
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <cstdio>
#include <filesystem>
#include <iostream>

#include "server/catalog.h"
#include "server/encode_cache.h"
#include "server/models_folder.h"
#include "server/server.h"
#include "server/server_options.h"

using namespace meshstream::server;

namespace {

int fail(const std::string& message) {
  std::cerr << "meshstream-server: " << message << "\n";
  return 1;
}

// The --models folder exists and is a folder; else the one-line reason.
std::string check_models_folder(const std::string& dir) {
  std::error_code ec;
  if (std::filesystem::is_directory(dir, ec)) return {};
  const char* what = std::filesystem::exists(dir, ec) ? "is not a folder" : "no such folder";
  return "--models " + dir + ": " + what +
         " (give the folder that holds your models, or --demo for the built-in ones)";
}

// Creates the cache folder if needed. An explicit --cache that cannot be
// used is an error (the caller exits 1); the default one falls back to
// encoding in memory with a warning. Returns the folder to use ("" = none).
meshstream::Result<std::string> prepare_cache(const ServerOptions& options) {
  if (options.cache_dir.empty()) return std::string();
  auto created = prepare_cache_folder(options.cache_dir, options.cache_dir_is_default);
  if (!created) {
    if (!options.cache_dir_is_default) {
      return meshstream::make_error(created.error().code, "--cache " + created.error().message);
    }
    spdlog::warn("cache {} unusable ({}); encoding in memory", options.cache_dir,
                 created.error().message);
    return std::string();
  }
  if (*created) spdlog::info("created cache folder {}", options.cache_dir);
  return options.cache_dir;
}

Catalog load_catalog(const ServerOptions& options, const std::string& cache_dir) {
  std::vector<std::unique_ptr<CatalogSource>> sources;
  if (!options.models_dir.empty()) {
    sources.push_back(models_folder_source({options.models_dir, cache_dir, 0}));
  }
  if (options.demo) sources.push_back(demo_source(cache_dir));
  Catalog catalog;
  for (auto& source : sources) {
    source->load(catalog, [](CatalogLogLevel level, const std::string& line) {
      if (level == CatalogLogLevel::kWarn) {
        spdlog::warn("catalog: {}", line);
      } else {
        spdlog::info("catalog: {}", line);
      }
    });
  }
  return catalog;
}

void log_catalog(const Catalog& catalog) {
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

  if (!options.models_dir.empty()) {
    if (const std::string problem = check_models_folder(options.models_dir); !problem.empty()) {
      return fail(problem);
    }
  }
  // Bind before loading: encoding a folder can take minutes, and a port in
  // use must not be found out only after that.
  Server server(options);
  if (auto status = server.listen(); !status) return fail(status.error().message);
  const auto endpoint = server.local_endpoint();
  spdlog::info("bound {}:{}; loading the models before serving", endpoint.address().to_string(),
               endpoint.port());

  const auto cache_dir = prepare_cache(options);
  if (!cache_dir) return fail(cache_dir.error().message);
  const Catalog catalog = load_catalog(options, *cache_dir);
  // (Once the server serves while it encodes, an empty folder will be a
  // folder to watch; until then a server with nothing to serve is a mistake.)
  if (catalog.size() == 0) {
    return fail(options.models_dir.empty()
                    ? std::string("no model to serve (this build cannot make the demo models)")
                    : "no model to serve in " + options.models_dir + " (the server reads files " +
                          "ending in " + served_extensions() + "; add some, or --demo)");
  }
  log_catalog(catalog);

  server.start_serving(catalog);
  std::printf("listening on %s:%u\n", endpoint.address().to_string().c_str(),
              unsigned(endpoint.port()));
  if (const auto metrics = server.metrics_endpoint()) {
    std::printf("metrics on %s:%u\n", metrics->address().to_string().c_str(),
                unsigned(metrics->port()));
  }
  std::fflush(stdout);
  server.run();
  return 0;
}
