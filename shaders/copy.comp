#version 450
#extension GL_GOOGLE_include_directive : require
// Pass-through (`none`) and the benchmark's floor: copies the input rect to the output rect, 4x4
// pixels per invocation on a CPU device like the other passes (15-19 % faster on lavapipe).
#include "common.glsl"

void processPixel(ivec2 p, ivec2 o) {
  const bool inRange = all(lessThan(p, P.src0Size));
  // The output is the input texel as is (`none` is a bit-exact pass-through, alpha included);
  // only the history, which later passes blend, is sanitised.
  vec4 texel = texelFetch(uSrc0, P.src0Offset + clamp(p, ivec2(0), P.src0Size - 1), 0);
  if (inRange) {
    if (kWriteHist) storeHistory(p, (kCleanSrc & 1) != 0 ? texel.rgb : sanitize(texel.rgb), texel.a, 1.0);
    if (kWriteOut) storeOutput(p, texel);
  }
}

void main() {
  ivec2 base = ivec2(gl_GlobalInvocationID.xy) * ivec2(kBlockW, kBlockH);
  if (any(greaterThanEqual(base, P.src0Size))) return;
  PROCESS_BLOCK(base);
}
