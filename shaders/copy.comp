#version 450
#extension GL_GOOGLE_include_directive : require
// Pass-through (`none`) and the benchmark's floor: copies the input rect to the output rect.
#include "common.glsl"

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(p, P.src0Rect.zw))) return;
  vec3 c = fetchSrc0(p);  // sanitised unless the input is 8-bit (finite by construction)
  if (kWriteHist) imageStore(uHistOut, p, vec4(c, 1.0));
  if (kWriteOut) writeOutput(p, c);
}
