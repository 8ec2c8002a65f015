// Shared declarations of the filter core's compute passes. Every pass uses the same descriptor
// set layout (unused bindings get 1x1 dummies) so the host side has one layout and one pool.


#extension GL_EXT_control_flow_attributes : require

#ifndef OUT_FORMAT
#define OUT_FORMAT rgba8
#endif

// Workgroup size: specialisation constants 11 and 12, chosen per device by the host (filter_record.cpp).
layout(local_size_x = 16, local_size_y = 8) in;
layout(local_size_x_id = 11, local_size_y_id = 12) in;

// Per-pipeline switches as specialisation constants: llvmpipe runs both sides of every branch
// under an execution mask, so a uniform switch still costs every path; constants fold away.
layout(constant_id = 0) const int kMode = 0;          // temporal: 0 taa, 1 hmtaa, 2 vtaa, 3 hybrid, 4 steady
layout(constant_id = 1) const int kSampleCount = 1;   // hmtaa/hybrid past samples (1..4)
layout(constant_id = 2) const bool kWriteOut = true;  // write uOut
layout(constant_id = 3) const bool kWriteHist = false;
layout(constant_id = 4) const bool kEncodeSrgb = false;
layout(constant_id = 5) const bool kSwapRB = false;
layout(constant_id = 6) const int kDepthBits = 0;     // bit0: this eye's depth, bit1: other eye's
layout(constant_id = 7) const int kCleanSrc = 0;      // bit0: src0, bit1: src1 is our own history (finite)
layout(constant_id = 8) const bool kJitter = false;   // src0 was rendered on a jittered grid
layout(constant_id = 9) const bool kCatmullRom = false;  // temporal: Catmull-Rom history sampling
layout(constant_id = 10) const bool kBlocked = true;     // temporal/stereo: 4x4 pixels per invocation
// History encoding (Params::historyFormat): 0 RGBA16F at binding 4; 1 RGBA8 UNORM at binding 8
// holding sqrt of linear colour, rounded with a dither (storeHistory); 2 the same rounded to
// nearest (format study only). The temporal pass decodes it (sampleSrc1Rgba); no other pass
// reads an 8-bit history (the filter keeps RGBA16F when the stereo pass follows, and with
// Catmull-Rom history sampling: its five taps decoded in line took llvmpipe twice as long to
// compile, dead code included).
layout(constant_id = 13) const int kHistoryEncoding = 0;
// Steady's clip-box switches: bit0 the one-sided curvature box (Params::steadyClipCurvatureCentred),
// bit1 the sRGB quantisation floor (Params::steadyClipQuantSrgb), bit2 the one-sided box only where
// the history lags on one side, kept in the sign of the RGBA16F history's alpha
// (Params::steadyClipCurvatureCentredGated), bit3 the box widened by the render's noise and bit4 the
// histogram that estimates it (Params::steadyNoiseEstimate), bit5 the residual's histogram (round 14),
// bit6 the frame's gain read and bit7 this dispatch the gain probe (Params::steadyGainCompensation);
// the later bits where filter_passes.cpp sets them (bit14: Params::steadyResolvedEdges, resolved_edge.glsl).
layout(constant_id = 14) const int kSteadyBoxSwitches = 0;

layout(set = 0, binding = 0) uniform sampler2D uSrc0;    // current colour / this eye
layout(set = 0, binding = 1) uniform sampler2D uSrc1;    // history / other eye
layout(set = 0, binding = 2) uniform sampler2D uDepth0;  // this eye's depth (texelFetch only)
layout(set = 0, binding = 3) uniform sampler2D uDepth1;  // other eye's depth
layout(set = 0, binding = 4, rgba16f) uniform writeonly image2D uHistOut;
layout(set = 0, binding = 5, OUT_FORMAT) uniform writeonly image2D uOut;
layout(set = 0, binding = 8, rgba8) uniform writeonly image2D uHistOut8;  // UNORM view of the 8-bit history

// This eye's input as the app submitted it: the alpha of every output (alphaOf). The history's
// alpha is the temporal method's own (steady: its sample count).
layout(set = 0, binding = 7) uniform sampler2D uAppInput;
layout(set = 0, binding = 10) uniform sampler2D uShownIn;  // the 8-bit output's codes last frame (hold)
layout(set = 0, binding = 11, rgba8) uniform writeonly image2D uShownOut;  // and this frame's

// Normalised depth n -> 1/z: 1/z = invNear + n * invFarMinusInvNear, n = (d - minDepth) *
// invDepthRange (invZFromDepth).
struct DepthToInvZ {
  float invNear;
  float invFarMinusInvNear;
  float minDepth;
  float invDepthRange;
};

// Must match PassUniforms in layer/core/src/pass_uniforms.h (std140; offsets checked there and
// by tests/core/filter_test_uniform_layout.cpp).
// A pass ignores the members it does not need; per-pipeline switches are the constants above.
layout(set = 0, binding = 6, std140) uniform PassParams {
  // (x, y, 1, 1/z) of this pixel -> homogeneous pixel coords in src1's rect: temporal, the
  // previous pose or the interpolated poses of seed 003 Eq. 1; stereo, [0] the other eye.
  mat4 reproj[4];
  vec4 sampleWeights;       // W(d_i), seed 003 Eq. 2, one per reprojection
  ivec2 src0Offset;         // src0's rect in its image; its size is also the dispatch size
  ivec2 src0Size;
  vec2 src0InvExtent;       // 1 / src0's image extent
  ivec2 src1Offset;         // src1's rect: the history (temporal) or the other eye (stereo)
  ivec2 src1Size;
  vec2 src1InvExtent;
  DepthToInvZ depth0;       // this eye's depth
  DepthToInvZ depth1;       // the other eye's depth (stereo)
  ivec2 depth0Offset;
  ivec2 depth1Offset;
  ivec2 outOffset;          // where pixel (0,0) goes in uOut
  ivec2 appInputOffset;     // uAppInput's rect offset (its size is src0's)
  vec2 jitterPx;            // src0's grid offset in pixels (its pixel c - jitter holds our pixel c)
  int historyValid;         // temporal: 0 after a reset or an invalid pose
  float taaAlpha;           // taa: weight of the current frame; steady: its constant alpha (ablation)
  float clipGamma;          // variance clip box mean +- gamma*sigma (taa, hybrid, stereo; steady's own)
  float alphaMin;           // vtaa, hybrid: lower clamp of alpha' (seed 002 Eq. 4)
  float shapeS;             // hmtaa, hybrid: S of seed 003 Eq. 4 (A(h) with w_min = 0); 1: h > h_max
  float wMin;               // hmtaa: w_min of seed 003 Eq. 5
  float wLowerBound;        // hmtaa: w_lb of seed 003 Eq. 5
  float fallbackInvZ;       // 1/z assumed without depth (1 / stereoFarDistanceM, 0 = infinity)
  float stereoDepthTolerance;    // stereo: relative depth difference that rejects the other eye
  float stereoBetaMin;           // stereo: lower clamp of beta (seed 002 Eq. 4)
  float steadyAlphaFloor;        // steady: alpha >= this; 1/floor caps the sample count
  float steadyConfidence;        // steady: 1 = alpha from the sample count, 0 = taaAlpha
  float steadyClipRejects;       // steady: 1 = a clip by t sigma divides the count by t^2 (mix weight)
  float steadyInvBlurBudgetPx2;  // steady: 1 / blur budget (0 = no bound)
  float steadyFootprint;         // steady: k of the [k, 1 - 2k, k]^2 footprint filter (0 = off)
  float steadyFootprintEncoded;  // steady: 1 = that filter on square roots, 0 = in linear light
  uint ditherSeed;               // the 8-bit history's dither: changes every frame (storeHistory)
  float stereoInverseVariance;     // stereo: 1 = beta by inverse error variance (after steady), 0 = seed 002 Eq. 4
  float stereoSampleCountScale;    // stereo: src alpha * this = the eye's sample count (>= 1); 0: count 1
  float stereoDisparitySpreadPx2;  // stereo without this eye's depth: the disparity's spread, px^2
  float steadyJitterRecentred;   // steady, jittered input: 1 = 3x3 weights follow the offset, 0 = raw sample
  float steadyHistoryBlurPerAxis;  // steady (history read): 1 = the blur guard per axis, 0 = summed
  float steadyClipHoldsCurrent;  // steady: 1 = the clip box reaches out to the current estimate fc
  float stereoTapCurvature;      // stereo: 1 = the other eye's bilinear tap corrected by this eye's curvature
  float steadyClipCurvatureKappa;  // steady: > 0 = the clip box bounded by kappa (|cxx| + |cyy|); 0 = off
  float steadyClipCurvatureInner;  // steady (round 7): the one-sided curvature box's inner bound (spec bit0)
  float steadyNoiseVariance;       // steady (round 13): the render's noise variance per linear RGB channel
  int probeBlockPx;                // steady's probe (round 17): one sample per block of this side
  float steadyOutputHold;          // steady (round 20): the 8-bit output's hysteresis, codes beyond 1/2
  int shownValid;                  // steady (round 20): 1 = last frame's shown codes are this pass's
  int headLockedStep;              // steady's probe (round 42): 0 none, 1 take the reference, 2 testify
  float headLockedInputDecoded;    // steady's probe (round 42): 1 = src0 is sRGB, read decoded to linear
  float headLockedDetailVariance;  // steady's probe (round 42): the frame's own finest detail, as a variance
} P;

vec3 sanitize(vec3 c) {
  // NaN/Inf must never reach the history: replace by black, clamp to the half-float range.
  bvec3 bad = bvec3(isnan(c.x) || isinf(c.x), isnan(c.y) || isinf(c.y), isnan(c.z) || isinf(c.z));
  return clamp(mix(c, vec3(0.0), bad), vec3(0.0), vec3(65000.0));
}

// Steady (mode 4) takes jittered samples where they lie, point samples at jitterPx from its pixel
// centres (temporal.comp, its footprint); the other temporal methods un-jitter through a bilinear fetch.
const bool kUnjitterBilinear = kJitter && kMode != 4;

// A jitter of exactly 0 is an unjittered frame: the layer's Halton offsets are never both 0, and it passes 0
// for a view whose fov the app did not echo.
bool frameIsJittered() { return kJitter && any(notEqual(P.jitterPx, vec2(0.0))); }

// Bilinear tap of src0 at q in its rect's pixel units (texel centres at +0.5), unclamped and unsanitised.
vec4 tapSrc0(vec2 q) { return textureLod(uSrc0, (vec2(P.src0Offset) + q) * P.src0InvExtent, 0.0); }

// The alpha comes along unsanitised (only alphaOf's use of it is exact: unjittered).
vec4 fetchSrc0Rgba(ivec2 p) {
  p = clamp(p, ivec2(0), P.src0Size - 1);
  vec4 c;
  if (kUnjitterBilinear) {  // un-jitter: bilinear at our pixel centre on src0's grid, inside its rect
    vec2 q = clamp(vec2(p) + 0.5 - P.jitterPx, vec2(0.5), vec2(P.src0Size) - 0.5);
    c = tapSrc0(q);
  } else {
    c = texelFetch(uSrc0, P.src0Offset + p, 0);
  }
  return vec4((kCleanSrc & 1) != 0 ? c.rgb : sanitize(c.rgb), c.a);
}
vec3 fetchSrc0(ivec2 p) { return fetchSrc0Rgba(p).rgb; }

// On a CPU device every pass but fxaa runs 4x4 pixels per invocation (kBlocked): the sixteen 3x3
// neighbourhoods of temporal and stereo share one 6x6 block of src0 fetches (36 instead of 144),
// and on llvmpipe fetches dominate the cost; passes that share no fetches gain too (figures at
// blockPixels in filter_record.cpp). On a GPU one pixel per invocation: neighbouring invocations touch
// neighbouring texels, so a warp's loads and stores coalesce and the texture cache serves the 3x3.
// Loops over the block carry [[unroll]] and per-pixel calls are written out: a loop that is not
// unrolled leaves the block arrays in memory on llvmpipe (measured at 1024x1024: the default
// pipeline at 4.9x the copy pass without [[unroll]], 3.5x with it).
const int kBlockW = kBlocked ? 4 : 1;
const int kBlockH = kBlocked ? 4 : 1;
const int kTileW = kBlockW + 2;
vec3 gBlock[6 * 6];  // (kBlockW + 2) * (kBlockH + 2) at most
// 3-row column sums per output row of the block, shared by the (up to) three 3x3 windows that
// contain the column: of c, of c*c and of the cross products (rg, rb, gb). Summing columns once
// and windows from them costs a third of summing nine taps per pixel.
vec3 gCol1[6 * 4], gCol2[6 * 4], gColX[6 * 4];
vec3 crossProducts(vec3 c) { return vec3(c.r * c.g, c.r * c.b, c.g * c.b); }
// src0's alpha at the block's own pixels: in the temporal pass src0 is the app's input, so an
// unjittered fetch there is alphaOf's (blockAlphaOf), and the output needs no fetch of its own.
float gAlpha[4 * 4];
void loadBlock(ivec2 base, bool withCross) {
  [[unroll]] for (int j = 0; j < kBlockH + 2; ++j)
    [[unroll]] for (int i = 0; i < kTileW; ++i) {
      vec4 texel = fetchSrc0Rgba(base + ivec2(i - 1, j - 1));
      gBlock[j * kTileW + i] = texel.rgb;
      if (i >= 1 && i <= kBlockW && j >= 1 && j <= kBlockH) gAlpha[(j - 1) * kBlockW + (i - 1)] = texel.a;
    }
  [[unroll]] for (int r = 0; r < kBlockH; ++r)
    [[unroll]] for (int i = 0; i < kTileW; ++i) {
      vec3 a = gBlock[r * kTileW + i], b = gBlock[(r + 1) * kTileW + i], c = gBlock[(r + 2) * kTileW + i];
      gCol1[r * kTileW + i] = a + b + c;
      gCol2[r * kTileW + i] = a * a + b * b + c * c;
      if (withCross) gColX[r * kTileW + i] = crossProducts(a) + crossProducts(b) + crossProducts(c);
    }
}
vec3 blockAt(ivec2 o, int x, int y) { return gBlock[(o.y + 1 + y) * kTileW + (o.x + 1 + x)]; }

// Sums over the 3x3 window of block pixel o: s1 of c, s2 of c*c, sx of (rg, rb, gb).
void windowSums(ivec2 o, bool withCross, out vec3 s1, out vec3 s2, out vec3 sx) {
  int k = o.y * kTileW + o.x;
  s1 = gCol1[k] + gCol1[k + 1] + gCol1[k + 2];
  s2 = gCol2[k] + gCol2[k + 1] + gCol2[k + 2];
  sx = withCross ? gColX[k] + gColX[k + 1] + gColX[k + 2] : vec3(0.0);
}

// Runs the including pass's processPixel(p, o) on every pixel of the block at base: one pixel, or
// the 4x4 block written out call by call (see above). processPixel has no early return and no
// branch around a texture read: llvmpipe runs everything after a divergent branch under an
// execution mask and samples lane by lane there. Pixels of a partial block past the edge compute
// on clamped coordinates, and their stores alone are skipped.
#define PROCESS_BLOCK(base) \
  processPixel(base, ivec2(0, 0)); \
  if (kBlocked) { \
    processPixel(base + ivec2(1, 0), ivec2(1, 0)); \
    processPixel(base + ivec2(2, 0), ivec2(2, 0)); \
    processPixel(base + ivec2(3, 0), ivec2(3, 0)); \
    processPixel(base + ivec2(0, 1), ivec2(0, 1)); \
    processPixel(base + ivec2(1, 1), ivec2(1, 1)); \
    processPixel(base + ivec2(2, 1), ivec2(2, 1)); \
    processPixel(base + ivec2(3, 1), ivec2(3, 1)); \
    processPixel(base + ivec2(0, 2), ivec2(0, 2)); \
    processPixel(base + ivec2(1, 2), ivec2(1, 2)); \
    processPixel(base + ivec2(2, 2), ivec2(2, 2)); \
    processPixel(base + ivec2(3, 2), ivec2(3, 2)); \
    processPixel(base + ivec2(0, 3), ivec2(0, 3)); \
    processPixel(base + ivec2(1, 3), ivec2(1, 3)); \
    processPixel(base + ivec2(2, 3), ivec2(2, 3)); \
    processPixel(base + ivec2(3, 3), ivec2(3, 3)); \
  }

// The 8-bit history's texel at integer texel coords t: linear colour (the square of the stored
// value) and the alpha as stored.
vec4 history8Texel(ivec2 t) {
  vec4 v = texelFetch(uSrc1, P.src1Offset + clamp(t, ivec2(0), P.src1Size - 1), 0);
  return vec4(v.rgb * v.rgb, v.a);
}
// Bilinear tap of src1 at normalised coords uv. The 8-bit history is filtered after decoding (four
// texel fetches): filtering sqrt-encoded texels and squaring would darken every edge a little on
// each sub-pixel reprojection (by f(1-f)(sqrt a - sqrt b)^2), and the history feeds back.
vec4 tapSrc1(vec2 uv) {
  if (kHistoryEncoding == 0) return textureLod(uSrc1, uv, 0.0);
  vec2 pos = uv / P.src1InvExtent - vec2(P.src1Offset) - 0.5;  // texel centres at integers
  ivec2 t = ivec2(floor(pos));
  vec2 f = pos - vec2(t);
  vec4 top = mix(history8Texel(t), history8Texel(t + ivec2(1, 0)), f.x);
  vec4 bottom = mix(history8Texel(t + ivec2(0, 1)), history8Texel(t + ivec2(1, 1)), f.x);
  return mix(top, bottom, f.y);
}

// Bilinear sample of src1 at continuous pixel coords q (pixel centres at +0.5) of its rect.
// The alpha comes along unsanitised: only the history's (our own, finite) alpha is ever used.
vec4 sampleSrc1Rgba(vec2 q) {
  q = clamp(q, vec2(0.5), vec2(P.src1Size) - 0.5);
  vec4 c = tapSrc1((vec2(P.src1Offset) + q) * P.src1InvExtent);
  return vec4((kCleanSrc & 2) != 0 ? c.rgb : sanitize(c.rgb), c.a);
}
vec3 sampleSrc1(vec2 q) { return sampleSrc1Rgba(q).rgb; }

// Catmull-Rom sample of src1 (the history) at continuous pixel coords q, from five bilinear taps
// (the four corner taps, whose weights are tiny, dropped and the rest renormalised; Jimenez 2016,
// as Bevy's and INSIDE's TAA do): bilinear resampling blurs the history a little on every frame
// of sub-pixel head tremor, and the blur accumulates; Catmull-Rom keeps it sharp. Its negative
// lobes can overshoot, so the result is clamped at 0 (the clip that follows bounds the rest).
vec4 sampleSrc1CatmullRom(vec2 q) {
  q = clamp(q, vec2(0.5), vec2(P.src1Size) - 0.5);
  vec2 pos = q - 0.5;  // texel centres at integers
  vec2 c = floor(pos);
  vec2 f = pos - c;
  vec2 w0 = f * (-0.5 + f * (1.0 - 0.5 * f));
  vec2 w1 = 1.0 + f * f * (-2.5 + 1.5 * f);
  vec2 w2 = f * (0.5 + f * (2.0 - 1.5 * f));
  vec2 w3 = f * f * (-0.5 + 0.5 * f);
  vec2 w12 = w1 + w2;
  vec2 t0 = (vec2(P.src1Offset) + c - 0.5) * P.src1InvExtent;  // centre of texel c - 1
  vec2 t3 = (vec2(P.src1Offset) + c + 2.5) * P.src1InvExtent;  // centre of texel c + 2
  vec2 t12 = (vec2(P.src1Offset) + c + 0.5 + w2 / w12) * P.src1InvExtent;
  vec4 r = textureLod(uSrc1, vec2(t12.x, t0.y), 0.0) * (w12.x * w0.y) +
           textureLod(uSrc1, vec2(t0.x, t12.y), 0.0) * (w0.x * w12.y) +
           textureLod(uSrc1, t12, 0.0) * (w12.x * w12.y) +
           textureLod(uSrc1, vec2(t3.x, t12.y), 0.0) * (w3.x * w12.y) +
           textureLod(uSrc1, vec2(t12.x, t3.y), 0.0) * (w12.x * w3.y);
  float wsum = w12.x * w0.y + w0.x * w12.y + w12.x * w12.y + w3.x * w12.y + w12.x * w3.y;
  r = max(r / wsum, vec4(0.0));
  return vec4((kCleanSrc & 2) != 0 ? r.rgb : sanitize(r.rgb), r.a);
}

// The history at q, its alpha included (steady keeps its sample count there).
vec4 sampleHistoryRgba(vec2 q) { return kCatmullRom ? sampleSrc1CatmullRom(q) : sampleSrc1Rgba(q); }
vec3 sampleHistory(vec2 q) { return sampleHistoryRgba(q).rgb; }

// Variance clipping: clips h towards the box centre mn onto the box mn +- ext, given ext^2. The
// largest |h - mn| / ext decides, so squares do without the square roots of sigma.
vec3 clipToBox(vec3 h, vec3 mn, vec3 ext2) {
  vec3 d = h - mn;
  vec3 t2 = d * d / ext2;
  float mx2 = max(t2.x, max(t2.y, t2.z));
  return mx2 > 1.0 ? mn + d * inversesqrt(mx2) : h;
}

float invZFromDepth(float d, DepthToInvZ m) {
  float n = clamp((d - m.minDepth) * m.invDepthRange, 0.0, 1.0);
  return max(m.invNear + n * m.invFarMinusInvNear, 0.0);  // 1/z is linear in the stored depth
}

float linearToSrgb1(float c) {
  return c <= 0.0031308 ? c * 12.92 : 1.055 * pow(c, 1.0 / 2.4) - 0.055;
}

// Alpha is carried through, never filtered: the filters remove colour aliasing, and a
// projection layer's alpha is a blend/passthrough mask, not colour. Averaged over time or taken
// from the other eye it would smear the mask's edges or leak one eye's mask into the other, and a
// layer's alpha must reach the compositor exactly as the app wrote it. So every pass outputs the
// app's input alpha at the same pixel (uAppInput: also in the stereo pass, whose src0 is then
// this frame's history). (Unpremultiplied layers: layer/xr/README.md.)
float alphaOf(ivec2 p) {
  return texelFetch(uAppInput, P.appInputOffset + clamp(p, ivec2(0), P.src0Size - 1), 0).a;
}

// Uniform in [0, 1) per pixel and frame (ditherSeed changes every frame): hash "lowbias32"
// (Chris Wellons, hash-prospector) of the pixel and the seed.
float ditherThreshold(ivec2 p) {
  uint h = uint(p.x) * 0x8da6b343u ^ uint(p.y) * 0xd8163841u ^ P.ditherSeed * 0xcb1ab31fu;
  h ^= h >> 16;
  h *= 0x7feb352du;
  h ^= h >> 15;
  h *= 0x846ca68bu;
  h ^= h >> 16;
  return float(h >> 8) * (1.0 / 16777216.0);
}

// Stores a history texel: linear c and the method's count (steady's sample count; 1 otherwise).
// The 8-bit history holds sqrt(c) (levels about as fine as sRGB's over [0, 1], finer near black;
// decoded by a multiply, so write and read are exact inverses on every device, which an sRGB view
// is not: lavapipe's sRGB decode is off by ~2 % in the dark, and the history feeds that back
// 1/alpha = 16 times over) and count * countScale8 in [0, 1] (steady: count / its cap).
// The rounding is dithered: a blend step alpha * |cur - hist| under half a level (alpha = 1/16:
// eight levels apart) would round back to the old level every frame and stall. Level k + 1 is
// taken with the probability that makes the expected decoded value c exactly (the levels decode
// to k^2 and (k+1)^2), so the history follows in expectation.
void storeHistory(ivec2 p, vec3 c, float count, float countScale8) {
  if (kHistoryEncoding == 0) {
    imageStore(uHistOut, p, vec4(c, count));
  } else {
    vec3 v = clamp(c, 0.0, 1.0) * (255.0 * 255.0);  // in squared levels
    vec3 k = min(floor(sqrt(v)), vec3(254.0));
    vec3 up = kHistoryEncoding == 1 ? step(vec3(ditherThreshold(p)), (v - k * k) / (2.0 * k + 1.0))
                                    : step(vec3(k + 0.5), sqrt(v));
    imageStore(uHistOut8, p, vec4((k + up) * (1.0 / 255.0), clamp(count * countScale8, 0.0, 1.0)));
  }
}

// After fxaa the history is only the stereo pass's src0; its alpha goes unread.
void writeHistory(ivec2 p, vec3 c) { storeHistory(p, c, 1.0, 1.0); }

vec3 linearToSrgb(vec3 c) { return vec3(linearToSrgb1(c.r), linearToSrgb1(c.g), linearToSrgb1(c.b)); }

// o as the target holds it (encoded, RGBA order): swapped for a BGRA target and stored.
void storeOutputTexel(ivec2 p, vec4 o) {
  if (kSwapRB) o = o.bgra;
  imageStore(uOut, P.outOffset + p, o);
}

// o: linear RGBA; encoded for an sRGB target (alpha is linear in every format, never encoded).
void storeOutput(ivec2 p, vec4 o) {
  if (kEncodeSrgb) o.rgb = linearToSrgb(clamp(o.rgb, 0.0, 1.0));
  storeOutputTexel(p, o);
}

// 8-bit output codes (unrounded) of linear c: the pass's own sRGB encoding, or UNORM's codes.
vec3 outputCodes(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  return 255.0 * (kEncodeSrgb ? linearToSrgb(c) : c);
}

// Output codes per unit of linear light at c (clamped), given its codes (outputCodes(c)): for sRGB,
// IEC 61966-2-1's slope 255 * (1.055 / 2.4) c^(-7/12), which is (code + 255 * 0.055) / (2.4 c) above
// the toe (no pow), and 255 * 12.92 in it.
vec3 codesPerLinear(vec3 c, vec3 code) {
  if (!kEncodeSrgb) return vec3(255.0);
  const vec3 aboveToe = (code + 255.0 * 0.055) / (2.4 * max(c, vec3(0.0031308)));
  return mix(aboveToe, vec3(255.0 * 12.92), lessThanEqual(c, vec3(0.0031308)));
}

// Round 20 (Params::steadyOutputHold): an 8-bit output with hysteresis. Each channel keeps the code
// it showed last frame, at the texel the reprojection came from, while the estimate c lies within
// 1/2 + hold codes of it and moved by less than half a code since last frame (`before`: last frame's
// estimate there); elsewhere it rounds. Rounding alone flips a code wherever an estimate that hovers
// at a boundary crosses it, frame after frame, though the picture did not change by a code. A change
// of half a code or more a frame (a fade) is shown as rounding shows it: held, a fade of 0.8 of a code
// a frame went in steps of two codes every other frame. Below half a code no code is skipped (that
// takes a move of 1 - hold). Round 21: the move is measured in linear light, in codes through the
// encoding's slope at c (its error is second order: up to 1 % of half a code, near code 20), not by encoding
// `before` too (three pows, about 0.45x the copy on lavapipe). The shown codes are written exactly
// (k / 255 stores as k). Round 40 (switch bit 12): the output is this frame's codes image itself, which the host
// copies to the app's image, so the codes are stored once, in the app's channel order (as last frame's were:
// the host drops them where the order changed, PassUniforms::shownValid).
void storeHeldOutput(ivec2 p, vec3 c, float alpha, bool shownBefore, vec2 from, vec3 before, float hold) {
  bool outputIsShown = (kSteadyBoxSwitches & 4096) != 0;  // not const: see temporal.comp's main
  bool shownSwapped = outputIsShown && kSwapRB;
  c = clamp(c, 0.0, 1.0);
  const vec3 code = outputCodes(c);
  vec3 shown = round(code);
  if (shownBefore) {
    const vec4 lastTexel = texelFetch(uShownIn, clamp(ivec2(floor(from)), ivec2(0), P.src1Size - 1), 0);
    const vec3 last = round(255.0 * (shownSwapped ? lastTexel.bgr : lastTexel.rgb));
    const bvec3 nearLast = lessThanEqual(abs(code - last), vec3(0.5 + hold));
    const vec3 movedCodes = abs(c - clamp(before, 0.0, 1.0)) * codesPerLinear(c, code);
    const bvec3 barelyMoved = lessThanEqual(movedCodes, vec3(0.5));
    shown = mix(shown, last, vec3(nearLast) * vec3(barelyMoved));
  }
  if (!outputIsShown) imageStore(uShownOut, p, vec4(shown * (1.0 / 255.0), 1.0));
  storeOutputTexel(p, vec4(shown * (1.0 / 255.0), alpha));
}

void writeOutput(ivec2 p, vec3 c) { storeOutput(p, vec4(c, alphaOf(p))); }
// alphaOf(p) for block pixel o of a pass whose src0 is the app's input (after loadBlock).
float blockAlphaOf(ivec2 p, ivec2 o) { return kJitter ? alphaOf(p) : gAlpha[o.y * kBlockW + o.x]; }

// Reprojects pixel centre p (with 1/z) through matrix m; returns false when behind or outside.
bool reproject(mat4 m, vec2 pc, float invZ, out vec2 q, out float invZOther) {
  vec4 h = m * vec4(pc, 1.0, invZ);
  invZOther = 0.0;
  q = vec2(-1.0);
  if (!(h.z > 1e-12)) return false;
  q = h.xy / h.z;
  invZOther = h.w / h.z;
  vec2 size = vec2(P.src1Size);
  return all(greaterThanEqual(q, vec2(0.0))) && all(lessThanEqual(q, size));
}
