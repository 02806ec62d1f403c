// lines.vert.glsl — coloured lines and points in world space: the skeleton overlay (bones as
// lines, joints as points) and the ground grid. Vertices are rebuilt on the CPU each frame (a few
// hundred at most), so there is nothing to skin here.
#version 330 core

layout(location = 0) in vec3 a_position;
layout(location = 1) in vec4 a_color;

uniform mat4 u_view_projection;
uniform float u_point_size;

out vec4 v_color;

void main() {
  v_color = a_color;
  gl_PointSize = u_point_size;
  gl_Position = u_view_projection * vec4(a_position, 1.0);
}
