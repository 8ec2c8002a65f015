#version 450
// One textured quad in its local xy plane ([-0.5, 0.5]^2), no vertex buffer.
layout(push_constant) uniform Push {
  mat4 mvp;
  vec4 tint;   // rgb multiplies the texture; a = output weight (1, or 1/N when accumulating)
  vec4 uvST;   // uv scale (xy) and offset (zw)
  vec4 noise;  // x = amplitude of per-pixel noise, y = seed
} pc;
layout(location = 0) out vec2 uv;

const vec2 corners[6] = vec2[](vec2(-0.5, -0.5), vec2(0.5, -0.5), vec2(0.5, 0.5),
                               vec2(-0.5, -0.5), vec2(0.5, 0.5), vec2(-0.5, 0.5));

void main() {
  vec2 c = corners[gl_VertexIndex];
  uv = vec2(c.x + 0.5, 0.5 - c.y) * pc.uvST.xy + pc.uvST.zw;
  gl_Position = pc.mvp * vec4(c, 0.0, 1.0);
}
