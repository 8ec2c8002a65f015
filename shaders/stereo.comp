#version 450
#extension GL_GOOGLE_include_directive : require
// Stereo blending (seed 002 §4.1/§5.2): the other eye reprojected into this one (depth or a far
// plane), rejected by a depth check, clipped to this eye's 3x3 colour box mean +- gamma*sigma
// widened to hold this eye's pixel (gamma = taaClipGamma: a moving object or a depth-check miss
// cannot pull in a foreign colour), blended with beta from Eq. 4, beta >= stereoBetaMin. After
// steady: the other eye's tap freed of its bilinear blur first (tapBlur), the box's gamma sqrt(8)
// (Params::stereoClipGammaAfterSteady), beta from the eyes' error variances (stereoBeta). Display
// only.
#include "common.glsl"

// The variance of a pixel's own one-pixel box footprint, 1/12 + 1/12 px^2: what a single sample
// errs by, as a displacement, when it stands for the pixel's area average (steady's blur budget).
const float kFootprintVarPx2 = 1.0 / 6.0;

// Weight of this eye's estimate y against the other eye's x (reprojected, clipped). Seed 002:
// Eq. 4 with the clamp. After steady: inverse error variances (Params::stereoInverseVariance).
// Both eyes' estimates of the same surface point err independently, each like a sample displaced
// over the pixel's box divided by its sample count n; the other eye's estimate also went through
// a bilinear tap (f(1-f) px^2 per axis) and, without depth, a disparity known only within its
// spread. A displacement of variance v errs by about |grad|^2 v on a locally linear signal, so
// |grad|^2 cancels: equal counts and an exact tap give 1/2. With the tap's curvature term taken
// off (stereoTapCurvature), f(1-f) stays as the bound of what that second-order correction misses
// (texture near the sampling limit). Measured at full weight against 1/4 and 0 (docs/method-history.md,
// round 9): the lighter bounds raise RMSE in 14 and 22 corpus cases.
float stereoBeta(vec3 x, vec3 mn, float sigma2, ivec2 o, float otherAlpha, vec2 q) {
  vec3 d = x - mn;
  float e = dot(d, d) * (1.0 / 3.0) + sigma2;
  float betaEq4 = clamp(e > 1e-12 ? 1.0 - sigma2 / e : 0.0, P.stereoBetaMin, 1.0);
  // abs: steady's side gate keeps a sign in its count (Params::steadyClipCurvatureCentredGated).
  float countThis = max(abs(gAlpha[o.y * kBlockW + o.x]) * P.stereoSampleCountScale, 1.0);
  float countOther = max(abs(otherAlpha) * P.stereoSampleCountScale, 1.0);
  vec2 f = fract(q - 0.5);  // the bilinear tap's offset within the texel
  float varThis = kFootprintVarPx2 / countThis;
  float varOther = kFootprintVarPx2 / countOther + dot(f, 1.0 - f) + P.stereoDisparitySpreadPx2;
  // The model linearises the signal over the displacement; a disparity known only to more than a
  // pixel (no depth, a near surface possible) points at another surface point: no blend.
  float betaInverseVariance = P.stereoDisparitySpreadPx2 > 1.0 ? 1.0 : varOther / (varThis + varOther);
  return P.stereoInverseVariance > 0.5 ? betaInverseVariance : betaEq4;
}

// What a bilinear tap at q adds to the signal's value there: interpolating linearly between texels
// at offset f gives c(q) + (1/2) f(1-f) c'' per axis (Taylor to second order), a blur. The other
// eye sees the same surface (depth check), so this eye's second differences stand for its c''.
vec3 tapBlur(ivec2 o, vec2 q) {
  vec2 f = fract(q - 0.5);
  vec3 centre2 = 2.0 * blockAt(o, 0, 0);
  vec3 curvatureX = blockAt(o, -1, 0) + blockAt(o, 1, 0) - centre2;
  vec3 curvatureY = blockAt(o, 0, -1) + blockAt(o, 0, 1) - centre2;
  return 0.5 * (f.x * (1.0 - f.x) * curvatureX + f.y * (1.0 - f.y) * curvatureY);
}

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
  vec4 other = sampleSrc1Rgba(q);
  if (P.stereoTapCurvature > 0.5) other.rgb = max(other.rgb - tapBlur(o, q), vec3(0.0));
  vec3 x = clipToBox(other.rgb, mn, max(P.clipGamma * P.clipGamma * var, dy * dy) + 1e-12);
  float sigma2 = (var.r + var.g + var.b) * (1.0 / 3.0);
  float beta = stereoBeta(x, mn, sigma2, o, other.a, q);
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
