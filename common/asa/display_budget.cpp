// The display budget: re-run ASA with a coarser screen tolerance (or fewer
// levels) until the output fits. See display_budget.h.
#include "common/asa/display_budget.h"

#include <algorithm>
#include <cmath>

namespace meshstream {

float raised_tolerance(float tolerance, uint64_t input_faces, uint64_t faces, uint64_t max_faces) {
  const double added = static_cast<double>(faces) - static_cast<double>(input_faces);
  const double room =
      std::max(1.0, static_cast<double>(max_faces) - static_cast<double>(input_faces));
  const double factor = std::max(2.0, 1.1 * std::sqrt(std::max(1.0, added / room)));
  return static_cast<float>(tolerance * factor);
}

Status subdivide_within_budget(const Mesh& mesh, const AsaOptions& options, uint64_t max_faces,
                               AsaWorkspace& workspace, AsaResult& result, BudgetOutcome& outcome) {
  outcome = {};
  AsaOptions run = options;
  outcome.pixel_tolerance = options.view.enabled ? options.view.pixel_tolerance : 0;
  outcome.levels = options.levels;
  auto fits = [&] { return max_faces == 0 || result.mesh.face_count() <= max_faces; };
  if (auto ok = subdivide_into(mesh, run, workspace, result); !ok) return ok;
  ++outcome.runs;
  if (fits()) return {};
  outcome.limited = true;
  if (mesh.face_count() < max_faces) {
    if (run.view.enabled) {
      for (int attempt = 0; attempt < 8 && !fits(); ++attempt) {
        run.view.pixel_tolerance = raised_tolerance(run.view.pixel_tolerance, mesh.face_count(),
                                                    result.mesh.face_count(), max_faces);
        if (auto ok = subdivide_into(mesh, run, workspace, result); !ok) return ok;
        ++outcome.runs;
        outcome.pixel_tolerance = run.view.pixel_tolerance;
      }
    }
    while (!fits() && run.levels > 1) {
      --run.levels;
      if (auto ok = subdivide_into(mesh, run, workspace, result); !ok) return ok;
      ++outcome.runs;
    }
    outcome.levels = run.levels;
    if (fits()) return {};
  }
  // Not even one level fits (or the input alone is over): no ASA.
  run.levels = 0;
  outcome.levels = 0;
  return subdivide_into(mesh, run, workspace, result);
}

}  // namespace meshstream
