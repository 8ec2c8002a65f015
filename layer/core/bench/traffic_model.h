// Bytes-per-pixel model of the filter's passes: what each pass must move between memory and the
// shader per output pixel of one eye, printed by steadyxr-bench beside the measured cost so each
// change is judged against it.
//
// Cache assumption: a pass reads each texel of each image it touches from memory once. The 3x3
// neighbourhood and the bilinear taps of the reprojected history (a sub-pixel shift, so the four
// texels of a tap are the neighbours' too) hit the cache; so does the app input's alpha where the
// pass already reads that image (binding 7 = src0 in the temporal pass). A second image read at the
// same pixel costs its full texel. Writes are whole texels, once.
//
// The second set of figures counts the shader's memory instructions per pixel as issued, which
// is what llvmpipe pays for (each is a JIT loop over the SIMD lanes, docs/cost.md):
// a 4x4 block loads its 6x6 neighbourhood once (36/16 = 2.25 fetches per pixel), a bilinear tap is
// one sample instruction (four texels), a Catmull-Rom history five.
#pragma once

#include <vulkan/vulkan.h>

#include "steadyxr/core/params.h"

namespace steadyxr::bench {

struct Traffic {
  double readBytes = 0;   // per pixel of one eye, from memory (cache assumption above)
  double writeBytes = 0;  // per pixel of one eye
  double fetches = 0;     // texel fetches per pixel as issued (texelFetch: 1, blocked 3x3: 2.25)
  double samples = 0;     // filtered (bilinear) sample instructions per pixel
  double stores = 0;      // imageStore per pixel
  double total() const { return readBytes + writeBytes; }
};

// `inputFormat` is the app's input and output format; the history is
// core::historyTexelBytes(params, inputFormat) per texel.
Traffic modelTraffic(const core::Params& params, VkFormat inputFormat, bool blocked);

}  // namespace steadyxr::bench
