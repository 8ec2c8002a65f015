#version 450
#extension GL_GOOGLE_include_directive : require
// Stereo blending (seed 002 §4.1/§5.2): the other eye reprojected into this one (depth or a far
// plane), rejected by a depth check, clipped to this eye's 3x3 colour box mean +- gamma*sigma
// widened to hold this eye's pixel (gamma = taaClipGamma: a moving object or a depth-check miss
// cannot pull in a foreign colour), blended with beta from Eq. 4, beta >= stereoBetaMin.
// Display only.
#include "common.glsl"

// Branch-free around texture reads, the store skipped past the edge (see PROCESS_BLOCK).
void processPixel(ivec2 p, ivec2 o) {
  ivec2 size = P.src0Size;
  const bool inRange = all(lessThan(p, size));
  vec3 y = blockAt(o, 0, 0);
  vec3 s1, s2, sx;
  windowSums(o, false, s1, s2, sx);
  vec3 mn = s1 * (1.0 / 9.0);
  vec3 var = max(s2 * (1.0 / 9.0) - mn * mn, vec3(0.0));

  bool hasThis = (kDepthBits & 1) != 0;
  bool hasOther = (kDepthBits & 2) != 0;
  float invZ = P.fallbackInvZ;
  if (hasThis)
    invZ = invZFromDepth(texelFetch(uDepth0, P.depth0Offset + min(p, size - 1), 0).r, P.depth0);

  vec2 q;
  float izExpected;
  bool ok = reproject(P.reproj[0], vec2(p) + 0.5, invZ, q, izExpected);
  if (hasThis && hasOther) {
    ivec2 qi = clamp(ivec2(floor(q)), ivec2(0), P.src1Size - 1);
    float izOther = invZFromDepth(texelFetch(uDepth1, P.depth1Offset + qi, 0).r, P.depth1);
    // Relative depth difference |z_e - z_o| / z_e = |iz_o - iz_e| / iz_o (infinite depths match).
    ok = ok && abs(izOther - izExpected) <= P.stereoDepthTolerance * izOther + 1e-7;
  }
  // The box always holds this eye's own pixel: identical eyes stay unchanged.
  vec3 dy = y - mn;
  vec3 x = clipToBox(sampleSrc1(q), mn, max(P.clipGamma * P.clipGamma * var, dy * dy) + 1e-12);
  float sigma2 = (var.r + var.g + var.b) * (1.0 / 3.0);
  vec3 d = x - mn;
  float e = dot(d, d) * (1.0 / 3.0) + sigma2;
  float beta = e > 1e-12 ? 1.0 - sigma2 / e : 0.0;
  beta = clamp(beta, P.stereoBetaMin, 1.0);
  vec3 result = ok ? mix(x, y, beta) : y;
  if (any(isnan(result)) || any(isinf(result))) result = y;
  if (inRange) writeOutput(p, result);
}

void main() {
  ivec2 base = ivec2(gl_GlobalInvocationID.xy) * ivec2(kBlockW, kBlockH);
  if (any(greaterThanEqual(base, P.src0Size))) return;
  loadBlock(base, false);
  PROCESS_BLOCK(base);
}
