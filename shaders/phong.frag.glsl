// phong.frag.glsl — Phong shading with the seed thesis's terms: ambient 0.1, diffuse, specular
// strength 0.5 and shininess 32, all times the surface colour (material diffuse x vertex colour x
// diffuse map). A normal map (tangent space, needs tangents) bends the normal; a specular map
// scales the specular term; an occlusion map (a PBR source's) scales the ambient term, and the
// emissive colour (times an emissive map) is added. Surfaces are lit on the side that faces the eye: the normal is
// flipped when it points away from the viewer, not by gl_FrontFacing, because sources may be
// open, inconsistently wound, or placed by a mirroring bind matrix (which flips the winding but
// not the transformed normal). A non-zero u_flat_color.a replaces shading
// with that colour (wireframe overlay).
//
// Lighting is computed in linear light: colour maps are sampled through sRGB formats (the GPU
// decodes them), colours and vertex colours are linear (as glTF defines them), and the result is
// encoded to sRGB here, explicitly, rather than through GL_FRAMEBUFFER_SRGB, so the window, the
// offscreen framebuffer and the panel drawn over them need no sRGB-capable format. A normal map
// gives x and y (a BC5 map holds nothing else) and z is rebuilt as sqrt(1 - x^2 - y^2).
#version 330 core

in vec3 v_position;
in vec3 v_normal;
in vec4 v_tangent;
in vec2 v_uv;
in vec4 v_color;

uniform vec3 u_camera_position;
uniform vec3 u_light_direction;  // towards the light
uniform vec3 u_diffuse_color;
uniform float u_opacity;
uniform sampler2D u_diffuse_map;
uniform sampler2D u_normal_map;
uniform sampler2D u_specular_map;
uniform bool u_has_diffuse_map;
uniform bool u_has_normal_map;
uniform bool u_has_specular_map;
uniform sampler2D u_occlusion_map;
uniform sampler2D u_emissive_map;
uniform bool u_has_occlusion_map;
uniform bool u_has_emissive_map;
uniform vec3 u_emissive_color;
uniform vec4 u_flat_color;

out vec4 o_color;

const float kAmbient = 0.1;
const float kSpecularStrength = 0.5;
const float kShininess = 32.0;

vec3 linear_to_srgb(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}

void main() {
  if (u_flat_color.a > 0.0) {
    o_color = u_flat_color;
    return;
  }
  vec3 v = normalize(u_camera_position - v_position);
  vec3 n = normalize(v_normal);
  if (dot(n, v) < 0.0) n = -n;
  if (u_has_normal_map && dot(v_tangent.xyz, v_tangent.xyz) > 0.0) {
    vec3 t = normalize(v_tangent.xyz - n * dot(n, v_tangent.xyz));
    vec3 b = cross(n, t) * v_tangent.w;
    vec2 xy = texture(u_normal_map, v_uv).xy * 2.0 - 1.0;
    vec3 m = vec3(xy, sqrt(max(0.0, 1.0 - dot(xy, xy))));
    n = normalize(mat3(t, b, n) * m);
  }

  vec3 colour = u_diffuse_color * v_color.rgb;
  if (u_has_diffuse_map) colour *= texture(u_diffuse_map, v_uv).rgb;

  vec3 l = normalize(u_light_direction);
  float diffuse = max(dot(n, l), 0.0);
  float specular = kSpecularStrength * pow(max(dot(v, reflect(-l, n)), 0.0), kShininess);
  if (u_has_specular_map) specular *= texture(u_specular_map, v_uv).r;

  float ambient = kAmbient;
  if (u_has_occlusion_map) ambient *= texture(u_occlusion_map, v_uv).r;
  vec3 emission = u_emissive_color;
  if (u_has_emissive_map) emission *= texture(u_emissive_map, v_uv).rgb;

  vec3 linear = (ambient + diffuse + specular) * colour + emission;
  o_color = vec4(linear_to_srgb(linear), u_opacity);
}
