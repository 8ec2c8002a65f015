#version 450
layout(push_constant) uniform Push {
  mat4 mvp;
  vec4 tint;
  vec4 uvST;
  vec4 noise;
} pc;
layout(set = 0, binding = 0) uniform sampler2D tex;
layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 color;

uint hash(uint x) {
  x ^= x >> 16; x *= 0x7feb352du;
  x ^= x >> 15; x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

void main() {
  vec3 c = texture(tex, uv).rgb * pc.tint.rgb;
  if (pc.noise.x > 0.0) {
    // Zero-mean per-pixel, per-frame noise, as a low-sample Monte Carlo renderer leaves.
    uvec2 p = uvec2(gl_FragCoord.xy);
    uint h = hash(p.x + hash(p.y + hash(uint(pc.noise.y))));
    vec3 n = vec3(h & 1023u, (h >> 10) & 1023u, (h >> 20) & 1023u) / 1023.0 - 0.5;
    c = clamp(c + 2.0 * pc.noise.x * n, 0.0, 1.0);
  }
  color = vec4(c * pc.tint.a, pc.tint.a);
}
