// The uniform block as every compiled shader declares it (PassParams, read back from the embedded
// SPIR-V: member names and std140 Offset decorations) against the host's PassUniforms: the same
// members in the same order at the same offsets. The static_asserts in pass_uniforms.h pin the
// host side; this test ties the GLSL side to it.
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <map>
#include <ostream>
#include <set>
#include <string>
#include <vector>

#include "pass_uniforms.h"
#include "steadyxr/shaders/copy_rgba16f_spv.h"
#include "steadyxr/shaders/copy_rgba8_spv.h"
#include "steadyxr/shaders/fxaa_rgba16f_spv.h"
#include "steadyxr/shaders/fxaa_rgba8_spv.h"
#include "steadyxr/shaders/stereo_rgba16f_spv.h"
#include "steadyxr/shaders/stereo_rgba8_spv.h"
#include "steadyxr/shaders/temporal_rgba16f_spv.h"
#include "steadyxr/shaders/temporal_rgba8_spv.h"

using steadyxr::core::DepthToInvZ;
using steadyxr::core::PassUniforms;

namespace {

struct Member {
  std::string name;
  uint32_t offset = 0;
  bool operator==(const Member&) const = default;
};
void PrintTo(const Member& m, std::ostream* os) {
  *os << m.name << " at " << m.offset;
}

// From the SPIR-V specification: "Physical Layout of a SPIR-V Module" (a 5-word header, then
// instructions whose first word is word count << 16 | opcode), the opcode table (OpName 5,
// OpMemberName 6, OpMemberDecorate 72) and the Decoration table (Offset 35).
constexpr uint32_t kOpName = 5, kOpMemberName = 6, kOpMemberDecorate = 72, kDecorationOffset = 35;

std::string literalString(const uint32_t* words, size_t count) {
  std::string s;
  for (size_t i = 0; i < count; ++i)
    for (int b = 0; b < 4; ++b) {
      const char c = static_cast<char>((words[i] >> (8 * b)) & 0xffu);
      if (c == '\0') return s;
      s += c;
    }
  return s;
}

// The members of the laid-out struct type named `typeName` (glslang also emits an undecorated
// copy of a struct used outside the block), in declaration order, with their offsets.
std::vector<Member> structMembers(const uint32_t* spv, size_t words, const std::string& typeName) {
  std::map<uint32_t, std::string> names;
  std::map<uint32_t, std::map<uint32_t, Member>> members;  // type id -> index -> member
  std::set<uint32_t> laidOut;                              // type ids with Offset decorations
  for (size_t at = 5; at < words;) {
    const uint32_t count = spv[at] >> 16, op = spv[at] & 0xffffu;
    if (count == 0 || at + count > words) break;  // malformed: stop (the checks below then fail)
    const uint32_t* w = spv + at;
    if (op == kOpName && count >= 3) names[w[1]] = literalString(w + 2, count - 2);
    if (op == kOpMemberName && count >= 4) members[w[1]][w[2]].name = literalString(w + 3, count - 3);
    if (op == kOpMemberDecorate && count >= 5 && w[3] == kDecorationOffset) {
      members[w[1]][w[2]].offset = w[4];
      laidOut.insert(w[1]);
    }
    at += count;
  }
  for (const auto& [id, name] : names) {
    if (name != typeName || !laidOut.count(id)) continue;
    std::vector<Member> out;
    for (const auto& [index, m] : members[id]) out.push_back(m);
    return out;
  }
  return {};
}

#define HOST_MEMBER(type, m)                       \
  Member {                                         \
#m, static_cast < uint32_t>(offsetof(type, m)) \
  }

const std::vector<Member> kPassUniforms = {
    HOST_MEMBER(PassUniforms, reproj),
    HOST_MEMBER(PassUniforms, sampleWeights),
    HOST_MEMBER(PassUniforms, src0Offset),
    HOST_MEMBER(PassUniforms, src0Size),
    HOST_MEMBER(PassUniforms, src0InvExtent),
    HOST_MEMBER(PassUniforms, src1Offset),
    HOST_MEMBER(PassUniforms, src1Size),
    HOST_MEMBER(PassUniforms, src1InvExtent),
    HOST_MEMBER(PassUniforms, depth0),
    HOST_MEMBER(PassUniforms, depth1),
    HOST_MEMBER(PassUniforms, depth0Offset),
    HOST_MEMBER(PassUniforms, depth1Offset),
    HOST_MEMBER(PassUniforms, outOffset),
    HOST_MEMBER(PassUniforms, appInputOffset),
    HOST_MEMBER(PassUniforms, jitterPx),
    HOST_MEMBER(PassUniforms, historyValid),
    HOST_MEMBER(PassUniforms, taaAlpha),
    HOST_MEMBER(PassUniforms, clipGamma),
    HOST_MEMBER(PassUniforms, alphaMin),
    HOST_MEMBER(PassUniforms, shapeS),
    HOST_MEMBER(PassUniforms, wMin),
    HOST_MEMBER(PassUniforms, wLowerBound),
    HOST_MEMBER(PassUniforms, fallbackInvZ),
    HOST_MEMBER(PassUniforms, stereoDepthTolerance),
    HOST_MEMBER(PassUniforms, stereoBetaMin),
    HOST_MEMBER(PassUniforms, steadyAlphaFloor),
    HOST_MEMBER(PassUniforms, steadyConfidence),
    HOST_MEMBER(PassUniforms, steadyClipRejects),
    HOST_MEMBER(PassUniforms, steadyInvBlurBudgetPx2),
    HOST_MEMBER(PassUniforms, steadyFootprint),
    HOST_MEMBER(PassUniforms, steadyFootprintEncoded),
    HOST_MEMBER(PassUniforms, ditherSeed),
    HOST_MEMBER(PassUniforms, stereoInverseVariance),
    HOST_MEMBER(PassUniforms, stereoSampleCountScale),
    HOST_MEMBER(PassUniforms, stereoDisparitySpreadPx2),
    HOST_MEMBER(PassUniforms, steadyJitterRecentred),
    HOST_MEMBER(PassUniforms, steadyHistoryBlurPerAxis),
    HOST_MEMBER(PassUniforms, steadyClipHoldsCurrent),
    HOST_MEMBER(PassUniforms, stereoTapCurvature),
    HOST_MEMBER(PassUniforms, steadyClipCurvatureKappa),
    HOST_MEMBER(PassUniforms, steadyClipCurvatureInner),
    HOST_MEMBER(PassUniforms, steadyNoiseVariance),
    HOST_MEMBER(PassUniforms, probeBlockPx),
    HOST_MEMBER(PassUniforms, steadyOutputHold),
    HOST_MEMBER(PassUniforms, shownValid),
    HOST_MEMBER(PassUniforms, headLockedStep),
    HOST_MEMBER(PassUniforms, headLockedInputDecoded),
    HOST_MEMBER(PassUniforms, headLockedDetailVariance),
};
// The table lists every host member: the last one (4 bytes) ends the struct, up to its 16-byte
// alignment.
static_assert(offsetof(PassUniforms, headLockedDetailVariance) + sizeof(float) + 16 > sizeof(PassUniforms));

const std::vector<Member> kDepthToInvZ = {
    HOST_MEMBER(DepthToInvZ, invNear),
    HOST_MEMBER(DepthToInvZ, invFarMinusInvNear),
    HOST_MEMBER(DepthToInvZ, minDepth),
    HOST_MEMBER(DepthToInvZ, invDepthRange),
};
static_assert(sizeof(DepthToInvZ) == 16);

struct Shader {
  const char* name;
  const uint32_t* spv;
  size_t words;
};
#define SHADER(s)                       \
  Shader {                              \
#s, s, sizeof(s) / sizeof(uint32_t) \
  }

}  // namespace

TEST(UniformLayout, EveryShaderDeclaresPassUniformsMemberForMember) {
  for (const Shader& s : {SHADER(copy_rgba8_spv), SHADER(copy_rgba16f_spv), SHADER(temporal_rgba8_spv),
                          SHADER(temporal_rgba16f_spv), SHADER(stereo_rgba8_spv), SHADER(stereo_rgba16f_spv),
                          SHADER(fxaa_rgba8_spv), SHADER(fxaa_rgba16f_spv)}) {
    ASSERT_GT(s.words, 5u);
    EXPECT_EQ(s.spv[0], 0x07230203u) << s.name << ": not SPIR-V";  // the magic number
    const std::vector<Member> block = structMembers(s.spv, s.words, "PassParams");
    ASSERT_EQ(block.size(), kPassUniforms.size()) << s.name;
    for (size_t i = 0; i < block.size(); ++i)
      EXPECT_EQ(block[i], kPassUniforms[i]) << s.name << " member " << i << " (shader, host)";
    EXPECT_EQ(structMembers(s.spv, s.words, "DepthToInvZ"), kDepthToInvZ) << s.name;
  }
}
