// meshstream-server: parse options -> check the folders -> bind the address
// -> announce the port -> serve until SIGINT/SIGTERM while the folder
// watcher and the encoder pool fill the model registry in the background ->
// exit 0. Bad input (a folder that is not there, an address in use, nothing
// that could ever be served) exits 1 with one line.
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>

#include "common/base/heap.h"
#include "server/catalog.h"
#include "server/encode_cache.h"
#include "server/encoder_pool.h"
#include "server/folder_watcher.h"
#include "server/model_registry.h"
#include "server/model_sources.h"
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

void log_catalog_line(CatalogLogLevel level, const std::string& line) {
  if (level == CatalogLogLevel::kWarn) {
    spdlog::warn("catalog: {}", line);
  } else {
    spdlog::info("catalog: {}", line);
  }
}

// With --watch off, a folder that holds nothing the server reads will never
// serve anything: the one-line reason, else "".
std::string nothing_to_serve(const ServerOptions& options) {
  const bool demo = options.demo && demo_models_available();
  if (demo) return {};
  if (options.models_dir.empty())
    return "no model to serve (this build cannot make the demo models)";
  if (options.watch != "off") return {};
  auto scan = scan_models_folder(options.models_dir);
  if (scan && (!scan->hcs.empty() || !scan->meshes.empty())) return {};
  return "no model to serve in " + options.models_dir + " (the server reads files ending in " +
         served_extensions() + "; add some, or --demo)";
}

WatchMode watch_mode(const std::string& text) {
  return text == "poll" ? WatchMode::kPoll : text == "off" ? WatchMode::kOff : WatchMode::kAuto;
}

}  // namespace

int main(int argc, char** argv) {
  meshstream::keep_heap_tight();  // peak RSS of encodes (heap.h)
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
  // Bind first, and listen at once: the models are encoded in the
  // background while the server serves.
  Server server(options);
  if (auto status = server.listen(); !status) return fail(status.error().message);
  const auto endpoint = server.local_endpoint();
  const auto cache_dir = prepare_cache(options);
  if (!cache_dir) return fail(cache_dir.error().message);
  if (const std::string problem = nothing_to_serve(options); !problem.empty()) return fail(problem);

  const auto started = std::chrono::steady_clock::now();
  ModelRegistry registry;
  EncoderPool pool(registry, options.encoders, log_catalog_line);
  // One line once everything found at start is ready or failed (scripts and
  // tests wait for it: "initial models done").
  // With --watch off, nothing new will come: a server none of whose models
  // could be made is a mistake (exit 1), as it was before it watched.
  std::atomic<bool> nothing_ready{false};
  auto report_initial = [&] {
    const StateCounts counts = registry.counts();
    spdlog::info("catalog: initial models done: {} ready, {} failed in {:.2f} s", counts.ready,
                 counts.failed,
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
    server.initial_models_done();
    if (counts.ready == 0 && options.watch == "off") {
      nothing_ready = true;
      server.stop();
    }
  };
  // Everything found at start is listed (queued) before the port is
  // announced: the folder's files first, then the demo models whose names
  // they leave free (a file of the same name wins, as it always has).
  std::unique_ptr<FolderWatcher> watcher;
  if (!options.models_dir.empty()) {
    watcher = std::make_unique<FolderWatcher>(
        FolderWatchOptions{options.models_dir, *cache_dir, watch_mode(options.watch)}, registry,
        pool, log_catalog_line);
    watcher->list_initial();
  }
  std::vector<EncodeTask> demo;
  if (options.demo) {
    if (!demo_models_available()) {
      spdlog::warn("catalog: --demo: this build has no procedural demo meshes or no encoder");
    }
    const auto taken = registry.snapshot();
    for (EncodeTask& task : demo_tasks(*cache_dir)) {
      if (taken->count(task.name)) {
        spdlog::warn("catalog: skipped demo model '{}': name is taken", task.name);
        continue;
      }
      if (watcher) watcher->reserve(task.name);
      registry.put(ModelStatus{task.name, task.source, task.origin, ModelState::kQueued, 0, "", "",
                               nullptr, 0});
      demo.push_back(std::move(task));
    }
  }
  // After the folder's first scan has submitted its files: the demo models,
  // then the line once all of them are done.
  auto after_first_scan = [&] {
    if (watcher && registry.counts().total() == 0) {
      spdlog::warn(
          "catalog: no model in {} yet (the server reads files ending in {}); serving them as "
          "they arrive",
          options.models_dir, served_extensions());
    }
    for (EncodeTask& task : demo) pool.submit(std::move(task));
    demo.clear();
    pool.when_idle(report_initial);
  };

  server.start_serving(registry);
  std::printf("listening on %s:%u\n", endpoint.address().to_string().c_str(),
              unsigned(endpoint.port()));
  if (const auto metrics = server.metrics_endpoint()) {
    std::printf("metrics on %s:%u\n", metrics->address().to_string().c_str(),
                unsigned(metrics->port()));
  }
  std::fflush(stdout);
  spdlog::info("serving while {} background encoder{} encode what is not cached", pool.encoders(),
               pool.encoders() == 1 ? "" : "s");
  if (watcher) {
    watcher->start(after_first_scan);
  } else {
    after_first_scan();
  }
  server.run();
  if (watcher) watcher->stop();
  const std::vector<std::string> running = pool.stop(std::chrono::milliseconds(0));
  if (!running.empty()) {
    // An encode cannot be interrupted and may take minutes: do not wait for
    // it (the cache only ever holds whole streams: temp file, then rename).
    std::string names;
    for (const std::string& name : running) names += (names.empty() ? "" : ", ") + name;
    spdlog::info("abandoning the encodes still running: {}", names);
    spdlog::shutdown();
    std::fflush(stdout);
    std::_Exit(0);
  }
  if (nothing_ready) {
    return fail("no model to serve in " + options.models_dir + " (the server reads files " +
                "ending in " + served_extensions() + "; add some, or --demo)");
  }
  return 0;
}
