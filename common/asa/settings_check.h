// Settings of ASA that cancel each other, refused by every program that
// takes them (the client, its viewer, `meshstream subdivide`) with the same
// words. ASA refines around an interior edge whose faces' normals satisfy
// N1.N2 <= t (flatness.cpp, mark_targets), and a crease angle C keeps an
// edge sharp, never a target, when N1.N2 < cos(C) (tag_feature_edges). When
// C < acos(t), cos(C) > t, so every edge ASA would split is sharp and ASA
// changes nothing: the options are almost certainly a mistake (a crease
// angle in the wrong unit, or meant for a lower t). --uniform ignores t,
// so creases at any angle make sense there.
#pragma once

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "common/asa/subdivide.h"

namespace meshstream {

// acos(t) in degrees: the smallest bend ASA's flatness test refines.
inline double flatness_angle_degrees(float flatness) {
  return std::acos(static_cast<double>(flatness)) * 180.0 / std::numbers::pi;
}

// "" when the options can refine something; otherwise the usage error,
// naming both values and the relation. `crease_flag` and `flatness_flag`
// are the programs' option names.
inline std::string asa_settings_problem(const AsaOptions& o, const std::string& crease_flag,
                                        const std::string& flatness_flag) {
  if (o.uniform || o.levels == 0 || o.crease_degrees <= 0) return "";
  const double limit = flatness_angle_degrees(o.flatness);
  if (o.crease_degrees >= limit) return "";
  char text[400];
  std::snprintf(text, sizeof text,
                "%s %g is below acos(%s %g) = %.1f degrees: every edge ASA would refine bends "
                "more than the crease angle, so it stays sharp and ASA changes nothing; use a "
                "crease angle of at least %.1f degrees or a flatness of at least cos(%g) = %.3f",
                crease_flag.c_str(), static_cast<double>(o.crease_degrees), flatness_flag.c_str(),
                static_cast<double>(o.flatness), limit, limit,
                static_cast<double>(o.crease_degrees),
                std::cos(static_cast<double>(o.crease_degrees) * std::numbers::pi / 180.0));
  return text;
}

}  // namespace meshstream
