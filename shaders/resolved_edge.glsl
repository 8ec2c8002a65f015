// Round 48 (Params::steadyResolvedEdges, README item 15): is this pixel beside a geometric edge that the
// app already resolved (its MSAA)? Then the app's image is already the pixel's area average, and the
// history's resampling blur and the footprint's leak across the step are error. Included by
// temporal.comp after common.glsl (blockAt, fetchSrc0, invZFromDepth).

const bool kResolvedEdges = kMode == 4 && (kSteadyBoxSwitches & 16384) != 0 && (kDepthBits & 1) != 0;

// The display's value of a linear colour's luma, gamma 2 standing in for sRGB (item 4's encoding); not the
// probe's displayedLuma, which encodes each channel exactly for the head-locked switch's thresholds.
float gamma2Luma(vec3 linearRgb) { return sqrt(dot(linearRgb, vec3(0.25, 0.5, 0.25))); }

float invZAt(ivec2 p, ivec2 size) {
  return invZFromDepth(texelFetch(uDepth0, P.depth0Offset + clamp(p, ivec2(0), size - 1), 0).r, P.depth0);
}

// Across the edge is the direction d of the 4-neighbour whose display luma differs most from this pixel's (the
// first of +x, -x, +y, -y on a tie). This pixel, the one behind it and its two neighbours along the edge agree
// to a code (a flat side: nothing for a history to add), the step to the pixel two across is over 4 codes
// (under it the blur's leak, at most an eighth of the step, rounds away), whose own next pixel agrees with it
// as closely (a flat far side), the pixel between is one mix of the two sides' colours in every channel with a
// coverage strictly between 1/8 and 7/8 (half of 4x MSAA's least step; a 1-sample render's geometric edge has
// no such pixel), and 1/z is not affine over this pixel, the one between and the one across (on a plane it is:
// a texture's filtered step on one surface mixes too). One direction only: where two neighbours differ, neither
// side is flat. Every other test reads the 3x3 the pass already holds; lavapipe runs every fetch in every pixel.
bool besideResolvedEdge(ivec2 o, ivec2 p, vec3 centre, float centreInvZ, ivec2 size) {
  const float oneCode = 1.0 / 255.0;
  const float here = gamma2Luma(centre);
  const vec3 right = blockAt(o, 1, 0), left = blockAt(o, -1, 0), below = blockAt(o, 0, 1), above = blockAt(o, 0, -1);
  const vec4 neighbours = vec4(gamma2Luma(right), gamma2Luma(left), gamma2Luma(below), gamma2Luma(above));
  const vec4 offsets = abs(neighbours - here);
  ivec2 d = ivec2(1, 0);
  vec3 between = right;  // selected, not indexed: lavapipe gathers an indexed private array lane by lane
  float most = offsets.x;
  if (offsets.y > most) { d = ivec2(-1, 0); between = left; most = offsets.y; }
  if (offsets.z > most) { d = ivec2(0, 1); between = below; most = offsets.z; }
  if (offsets.w > most) { d = ivec2(0, -1); between = above; }
  const vec3 across = fetchSrc0(p + 2 * d);
  const float stepAcross = gamma2Luma(across) - here;
  const float sideTolerance = min(abs(stepAcross) * 0.125, oneCode);
  // The other three neighbours within the tolerance: at most one of the four (the one across) is outside it.
  const int outside = int(dot(vec4(greaterThanEqual(offsets, vec4(sideTolerance))), vec4(1.0)));
  if (abs(stepAcross) <= 4.0 * oneCode || outside > 1 ||
      abs(gamma2Luma(fetchSrc0(p + 3 * d)) - gamma2Luma(across)) >= sideTolerance)
    return false;
  // The coverage that mixes the two sides closest to the pixel between (least squares over RGB).
  const vec3 span = across - centre;
  const float coverage = dot(between - centre, span) / max(dot(span, span), 1e-12);
  const vec3 mixed = max(centre + coverage * span, vec3(0.0));
  if (coverage <= 0.125 || coverage >= 0.875 || any(greaterThanEqual(abs(sqrt(between) - sqrt(mixed)), vec3(oneCode))))
    return false;
  const float secondDifference = centreInvZ - 2.0 * invZAt(p + d, size) + invZAt(p + 2 * d, size);
  return abs(secondDifference) > 1e-3 * abs(centreInvZ);
}
