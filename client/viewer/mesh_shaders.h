// GLSL 3.30 core sources of the mesh renderer (see mesh_renderer.h).
#pragma once

namespace meshstream::client::shaders {

inline constexpr const char* kVertex = R"(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in float a_distance;
layout(location = 3) in vec4 a_color;
layout(location = 4) in vec2 a_uv;
uniform mat4 u_view;
uniform mat4 u_projection;
out vec3 v_view_pos;
out vec3 v_view_normal;
out float v_distance;
out vec4 v_color;
out vec2 v_uv;
void main() {
  v_color = a_color;
  v_uv = a_uv;
  vec4 view_pos = u_view * vec4(a_position, 1.0);
  v_view_pos = view_pos.xyz;
  v_view_normal = mat3(u_view) * a_normal;  // the view has no scaling
  v_distance = a_distance;
  gl_Position = u_projection * view_pos;
}
)";

// Passes the triangle through and adds, per corner, its window-space height
// over the opposite edge; interpolated without perspective this is every
// fragment's distance in pixels to each of the three edges.
inline constexpr const char* kGeometry = R"(#version 330 core
layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;
in vec3 v_view_pos[];
in vec3 v_view_normal[];
in float v_distance[];
in vec4 v_color[];
in vec2 v_uv[];
uniform vec2 u_viewport;
// The first face of this draw call in the face-label buffer (faces are drawn
// in groups by texture, gl_PrimitiveIDIn counts from each group's start).
uniform int u_first_face;
out vec3 g_view_pos;
out vec3 g_view_normal;
out float g_distance;
out vec4 g_color;
out vec2 g_uv;
noperspective out vec3 g_edge_px;
flat out int g_face;
void main() {
  vec2 p[3];
  for (int i = 0; i < 3; ++i) {
    float w = max(gl_in[i].gl_Position.w, 1e-6);
    p[i] = 0.5 * u_viewport * gl_in[i].gl_Position.xy / w;
  }
  vec2 e0 = p[2] - p[1];
  vec2 e1 = p[2] - p[0];
  vec2 e2 = p[1] - p[0];
  float twice_area = abs(e1.x * e2.y - e1.y * e2.x);
  vec3 heights = vec3(twice_area / max(length(e0), 1e-6),
                      twice_area / max(length(e1), 1e-6),
                      twice_area / max(length(e2), 1e-6));
  for (int i = 0; i < 3; ++i) {
    g_view_pos = v_view_pos[i];
    g_view_normal = v_view_normal[i];
    g_distance = v_distance[i];
    g_color = v_color[i];
    g_uv = v_uv[i];
    g_edge_px = vec3(i == 0 ? heights.x : 0.0, i == 1 ? heights.y : 0.0, i == 2 ? heights.z : 0.0);
    g_face = u_first_face + gl_PrimitiveIDIn;
    gl_Position = gl_in[i].gl_Position;
    EmitVertex();
  }
  EndPrimitive();
}
)";

inline constexpr const char* kFragment = R"(#version 330 core
in vec3 g_view_pos;
in vec3 g_view_normal;
in float g_distance;
in vec4 g_color;
in vec2 g_uv;
noperspective in vec3 g_edge_px;
flat in int g_face;
uniform int u_coloring;
uniform int u_wireframe;
uniform float u_wire_width;
uniform float u_distance_max;
uniform usamplerBuffer u_face_kind;
// The surface's own look (ColorMode 0): per-vertex (or per-corner) base
// colour times the base colour texture, lit (u_surface 0), unlit without
// the texture (1: base colour), or the texture alone, unlit (2).
uniform int u_has_color;
uniform int u_has_texture;
uniform int u_surface;
uniform sampler2D u_base_texture;
out vec4 frag_color;

// Blue (0) - cyan - green - yellow - red (1).
vec3 ramp(float t) {
  t = clamp(t, 0.0, 1.0);
  vec3 c0 = vec3(0.15, 0.25, 0.85), c1 = vec3(0.10, 0.75, 0.85), c2 = vec3(0.30, 0.80, 0.30),
       c3 = vec3(0.95, 0.85, 0.20), c4 = vec3(0.90, 0.20, 0.15);
  if (t < 0.25) return mix(c0, c1, t * 4.0);
  if (t < 0.50) return mix(c1, c2, (t - 0.25) * 4.0);
  if (t < 0.75) return mix(c2, c3, (t - 0.50) * 4.0);
  return mix(c3, c4, (t - 0.75) * 4.0);
}

void main() {
  vec3 base = vec3(0.78, 0.76, 0.72);
  bool lit = true;
  if (u_coloring == 0 && (u_has_color != 0 || u_has_texture != 0)) {
    vec3 albedo = u_has_color != 0 ? g_color.rgb : vec3(1.0);
    vec3 texel = u_has_texture != 0 ? texture(u_base_texture, g_uv).rgb : vec3(1.0);
    if (u_surface == 1) {
      base = u_has_color != 0 ? albedo : base;
      lit = false;
    } else if (u_surface == 2) {
      base = u_has_texture != 0 ? texel : base;
      lit = false;
    } else {
      base = albedo * texel;
    }
  } else if (u_coloring == 1) {
    uint kind = texelFetch(u_face_kind, g_face).r;
    base = kind == 1u ? vec3(0.95, 0.55, 0.15) : (kind == 2u ? vec3(0.35, 0.80, 0.35)
                                                             : vec3(0.55, 0.62, 0.75));
  } else if (u_coloring == 2) {
    base = ramp(g_distance / max(u_distance_max, 1e-30));
  }
  vec3 n = normalize(g_view_normal);
  if (dot(n, n) < 0.5) n = vec3(0.0, 0.0, 1.0);
  if (!gl_FrontFacing) n = -n;
  vec3 v = normalize(-g_view_pos);
  vec3 key = normalize(vec3(-0.45, 0.65, 0.6));
  vec3 fill = normalize(vec3(0.6, -0.25, 0.75));
  float diffuse = max(dot(n, key), 0.0);
  float fill_light = max(dot(n, fill), 0.0);
  float specular = pow(max(dot(n, normalize(key + v)), 0.0), 48.0);
  vec3 color = lit ? base * (0.20 + 0.70 * diffuse + 0.30 * fill_light) + vec3(0.22) * specular
                  : base;
  if (u_wireframe != 0) {
    float d = min(g_edge_px.x, min(g_edge_px.y, g_edge_px.z));
    float coverage = 1.0 - smoothstep(u_wire_width * 0.5, u_wire_width * 0.5 + 1.0, d);
    color = mix(color, vec3(0.08, 0.08, 0.10), 0.85 * coverage);
  }
  frag_color = vec4(color, 1.0);
}
)";

}  // namespace meshstream::client::shaders
