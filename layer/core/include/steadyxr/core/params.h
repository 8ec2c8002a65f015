// Method selection and tunable parameters of the filter core. Value type; parse/format
// helpers report bad input as an error string instead of throwing.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace steadyxr::core {

enum class TemporalMethod : uint8_t {
  None,    // pass-through
  Fxaa,    // FXAA 3.11-style single-frame edge filter (seed 001 §4.3)
  Taa,     // pose reprojection + YCoCg 3x3 variance clipping + constant alpha (seed 001, 002 §4.2)
  Hmtaa,   // head-movement TAA, seed 003 Eq. 1-5
  Vtaa,    // variance-optimal blending, seed 002 Eq. 4, 10, 11
  Hybrid,  // hmtaa reprojection + A(h), with vtaa's per-pixel weight in place of the clip
  Steady,  // exact reprojection, confidence-weighted 1/N accumulation, YCoCg clip (README, method)
};

// The shipped default temporal method: decided by the evaluation (eval/), one line to change.
inline constexpr TemporalMethod kDefaultTemporalMethod = TemporalMethod::Steady;
// Whether the default adds the stereo pass. Off: on the corpus (README, the default; issue 14
// round 5) steady+stereo lowers the per-pixel stereo error to 69.8 % of none's against steady's
// 82.5 % and mean RMSE to 66.9 % against 67.6 %, but RMSE is higher in 11 of 120 cases (by at most
// 0.8 %), and where it blends it costs 4.95x the copy pass against steady's 3.05x (budget 3.5x).
inline constexpr bool kDefaultStereo = false;

// How the temporal passes resample the reprojected history.
enum class HistoryFilter : uint8_t {
  Bilinear,    // one bilinear tap: cheapest, blurs a little on every sub-pixel reprojection
  CatmullRom,  // five bilinear taps (Catmull-Rom without its corner taps): stays sharp
};

enum class InvocationBlock : uint8_t { Auto, OnePixel, FourByFour };

// How the temporal passes store their history (docs/cost.md: the format study).
enum class HistoryFormat : uint8_t {
  Rgba16f,  // 8 bytes per texel, linear light; the sample count in the alpha as is
  // 4 bytes: RGBA8 holding sqrt of linear colour with dithered rounding (a per-pixel, per-frame
  // threshold, so a blend step under half a level still moves the history in expectation instead
  // of stalling), decoded before bilinear filtering; the sample count in the alpha as a fraction
  // of its cap. Used for 8-bit inputs, without the stereo pass and with the bilinear history
  // filter only (filter.h, historyFormat): a float input may exceed [0, 1].
  Rgba8Dithered,
  Rgba8Nearest,  // as Rgba8Dithered with round-to-nearest: the stall, for the format study only
};

struct Params {
  TemporalMethod temporal = kDefaultTemporalMethod;
  bool stereo = kDefaultStereo;  // stereo blending after the temporal pass (display only)

  // taa
  float taaAlpha = 0.1f;      // weight of the current frame
  float taaClipGamma = 1.0f;  // clip box = mean +- gamma * sigma (YCoCg); also hybrid's history
                              // clip and stereo's clip of the other eye (RGB box)

  // hmtaa (seed 003 §5.2.2 defaults)
  float hMaxDegPerSec = 25.0f;
  float wMin = 0.3f;
  float wLowerBound = 0.1f;  // w_lb of Eq. 5
  static constexpr uint32_t kMaxSamples = 4;
  uint32_t sampleCount = 1;                                                      // n past samples
  std::array<float, kMaxSamples> sampleD{2.0f / 3.0f, 1.0f / 3.0f, 0.0f, 0.0f};  // d_i in [0,1]

  // vtaa / hybrid
  float vtaaAlphaMin = 0.05f;  // lower clamp of alpha' (the weight of the current frame)

  // steady: alpha = max(1 / (n + 1), steadyAlphaFloor), n the history's sample count (its alpha).
  // The floor: the layer's jitter cycles through 8 Halton(2,3) phases (layer/xr rewrite.cpp); an
  // exponential history with weight a holds an effective (2 - a) / a samples, so 1/16 (31
  // effective samples) holds every phase about four times over and more would only add lag.
  float steadyAlphaFloor = 1.0f / 16.0f;
  // Ablation switches of the steady method (README, ablation table).
  bool steadyConfidence = true;  // off: a constant alpha = taaAlpha, as taa
  // A clip of the history by t sigma (t > 1) divides n by t^2: a history the clip had to move is
  // evidence of a wrong history (a moving object, a disocclusion), so the current frame gets more
  // weight at once. On the corpus (clip gamma 0.5): mean RMSE 68.3 % of none's against 79.8 %
  // without, cases above none's 0 against 22, worst frame 1.36x none's against 1.95x (README,
  // ablation).
  bool steadyClipRejects = true;
  // The clip box reaches out, on the history's side and per YCoCg channel, to the current frame's
  // own estimate of the pixel's area average (the footprint filter's output). Issue 14 round 4;
  // not the default: it did not beat the narrow box on the corpus slices. Why it was tried: at a
  // peak (a 1-px line) the area average is near the pixel's own value, not within the 3x3 mean
  // +- 0.5 sigma, and a box that excludes the very value the history is blended towards clips the
  // history to a value the current frame itself calls wrong. Measured (s4-d notes): photos gain
  // (astronaut, mipmapped, tremor 1x: 0.701 of none's RMSE against 0.767), and so do held-out
  // pictures and the moving object; 1-px lines lose (0.489 against 0.365): there the narrow
  // clip's pull towards the 3x3 mean is what helps.
  bool steadyClipHoldsCurrent = false;
  // The clip box of the history: the YCoCg 3x3 mean +- steadyClipGamma * sigma. The history
  // estimates this pixel's area average. On a locally linear signal (slope g per px along x) the
  // 3x3 has sigma^2 = 2g^2/3 and the pixel's own footprint spans the mean +- g/2 = +- sqrt(3/8)
  // sigma (0.61): a history outside that is no average over this pixel of the current picture.
  // taa's gamma = 1 lets a moving object's edge ghost inside the wider box. Measured (README,
  // the default): at 0.61 one corpus case (moving object, tremor 0.5x) stays 0.5 % above none's
  // RMSE; 0.5 is the widest of {1, 0.75, 0.61, 0.5, 0.4} with every corpus case and every case of
  // a held-out run (other pictures, seed, size) at or below none's.
  float steadyClipGamma = 0.5f;
  // Issue 14 round 6 (the default since round 6): the clip box is also bounded by the 3x3's second
  // differences, ext = min(gamma sigma, kappa (|cxx| + |cyy|)) per YCoCg channel, cxx = c(-1,0) +
  // c(1,0) - 2c(0,0). Why: with exact reprojection of a static scene every legitimate difference
  // between the history and the box centre is second order (Taylor per axis, a blur of variance V
  // shifts a smooth signal by V c''/2: the area average V = 1/12, the 3x3 mean 2/3), while a lag
  // (a moving object, parallax without depth) is first order, gradient x displacement, and so is
  // sigma (a ramp of slope g: sigma = g sqrt(2/3)). On smooth texture the gamma sigma box admits a
  // lag of ~0.4 px where none's own error is second order; aliased detail and noise have large
  // second differences (noise: ~sqrt(6) sigma_noise), where the gamma sigma box stays.
  // Measured (README item 6, docs/evaluation-scenes.md "Slow motion"; 96 px corpus): moving object at 90 Hz
  // 0.845 of none's RMSE against 0.969 without it (0 cases above none against 4, worst frame 1.08x
  // against 1.21x); corpus at 30 Hz 0.674 against 0.676; the astronaut photo +1.6 % and the noisy
  // scene +4.8 % (a per-pixel second difference is a noisy estimate of c'': where it is small by
  // chance the box narrows). On because the promise (never worse than none) broke at VR app rates
  // without it, and the 30 Hz corpus does not get worse.
  bool steadyClipCurvature = true;
  // kappa: the largest legitimate |history - 3x3 mean| per unit |c''| per axis. The history is the
  // area average blurred by its bilinear taps (variance V in [1/12, 1/12 + 1/4 + 1/12]: the box, one
  // tap's f(1 - f) <= 1/4, the blur guard's accumulated 1/12 per axis); the mean is a blur of 2/3.
  // |V - 2/3| / 2 is largest at V = 1/12: 7/24 (a blurrier history lies nearer the mean). The
  // cross term cxy shifts neither (the box and the 3x3 are symmetric; a bilinear tap is exact on xy).
  float steadyClipCurvatureKappa = 7.0f / 24.0f;
  // Issue 14 round 7 (the default): the box of steadyClipCurvature made one-sided. A blur of
  // variance V per axis shifts a smooth signal by V c''/2; the 3x3 mean by (2/3) c''/2, a static
  // history of blur V_h by V_h c''/2, so history - mean = -(1/3 - V_h/2) c'' per axis: on one side
  // of the mean, between inner = 1/3 - V_max/2 and kappa = 1/3 - V_min/2 times -c''. The box is
  // that interval summed over x and y (centre -(kappa + inner)/2 (cxx + cyy), half-width
  // (kappa - inner)/2 (|cxx| + |cyy|), 3.5x narrower than kappa's symmetric box) where it is
  // narrower than gamma sigma, else the gamma sigma box about the mean. Why: content that changes
  // in place (a video's slow pan or zoom, a fade; eval scenes video, fade) is a lag the symmetric
  // box keeps (a history on the wrong side of the mean, up to 10/24 |c''| beyond where a static
  // one can be): with the symmetric box the video at the corpus's density is above none in 5 of 15
  // cases. What it costs: accuracy on detail that is not smooth over three samples (sub-pixel
  // wires, 1-px lines, small text: three samples cannot tell a wire from a parabola). README item 7.
  bool steadyClipCurvatureCentred = true;
  // Issue 14 round 10, an option, off (docs/method-history.md, "A temporal gate on item 7"): the
  // one-sided box only where the history lags on one side.
  // Content that changes in place leaves a history that stays on the same side of the current
  // frame's estimate (luma) frame after frame; a history that averages aliased detail under head
  // tremor falls on either side, as the frame's samples happen to land. So the one-sided box
  // applies where the history's luma lies on the same side of the footprint estimate as last
  // frame, elsewhere the symmetric box of steadyClipCurvature. The side is the sign of the
  // history's alpha (negative: above), no memory of its own; where the bilinear tap mixes signs the
  // count it reads comes out lower, the safe direction. RGBA16F history only (the 8-bit alpha has
  // no sign: there the box is one-sided everywhere). What it wins: most of the accuracy the
  // one-sided box cost on aliased detail (corpus 0.678 of none's against 0.702). Why it is off by
  // default: the first frame of a change cannot be told from aliasing by this bit, and 24 fps video at
  // 90 Hz makes every content frame a first frame (9 of 90 content cases with a frame above 1.10x
  // none's), and a head-locked HUD is content that moves in place too (held out: frames up to 1.21x).
  // For apps without video or a HUD drawn into the eye images.
  bool steadyClipCurvatureCentredGated = false;
  // Issue 14 rounds 13-15, the default since round 15 (README, the default's item 9): the render's
  // per-frame noise (a path tracer's, film grain, dithered transparency) estimated from the frames,
  // and the clip box widened by one pixel's noise variance: a history may differ from the box by as
  // much as the noisy render itself differs from the truth (none's own error). The estimate: Donoho
  // and Johnstone's robust scale, sigma = median |d| / 0.6745, over the luma's x^2 y^2 contrast d of
  // the 3x3 at one pixel in 16 (the finest diagonal detail; at most 1024 an eye since round 28: the
  // probe's, below), 3x3s with none of it (flat, masked) left out, from the newest frame the GPU has
  // finished. Why: without it the box (items 6 and 7, built from second differences) clips a good history to
  // a noisy centre, and plain taa beat the default on noisy renders. One frame cannot tell fine aliased
  // detail from noise; rounds 14 and 15 (below) keep a clean render's detail and a fade's lag out of it.
  // false: the default before round 15.
  bool steadyNoiseEstimate = true;
  // Round 14: the estimate confirmed over time (noise_estimate.h): the same detail of the residual
  // between this frame's footprint estimate and the reprojected history, the smallest of the last 4
  // frames, caps the frame's own. Noise is new in every frame; a picture's fine detail is in the
  // history too, and the window leaves out the first frames of a change in place (video below the
  // display rate). false: round 13's estimate (the frame's own detail alone).
  bool steadyNoiseResidualOverTime = true;
  // Round 15 (with steadyNoiseEstimate and steadyNoiseResidualOverTime): no noise allowance while the
  // residual's mean over the frame lies on one side of 0 in two frames in a row (a fade, any change of
  // the picture as a whole). Noise's residual averages out; a fade's lag is on one side in every pixel,
  // and a box widened by the noise lets it through (a clean fade reached 1.22x none's in a frame).
  // false: round 14's estimate.
  bool steadyNoiseChangeTest = true;
  // Issue 14 round 16 (the default; README item 10): a history the clip box rejects, relit by the frame's
  // gain. A fade or an exposure change of a fraction of an 8-bit code per frame moves every pixel by less
  // than its own rounding, so no 3x3 can tell it from aliasing, and where the box is its floor the lagging
  // history is clipped onto it (a dark fade's first frame reached 1.37x none's, held-out seed 40). The
  // whole frame can tell: before the temporal pass a probe sums, at one pixel in 16 of both eyes (at most
  // 1024 an eye since round 28, filter_passes.h), the luma of this frame and of the reprojected history
  // (clamped to [0, 1]: HDR above 1 leans to no gain); where
  // their mean difference lies 4 standard errors from 0 (round 15's test) the gain is the ratio of the
  // sums, else 1. A pixel takes the relit history only where the box rejects the history as it was, the
  // relit one lies inside the box and nearer the frame's own estimate; the count still falls by the
  // unrelit history's t^2. A history the box admits keeps its value: a gain that drifts by tenths of a
  // percent (a video's zoom) would otherwise bias pixels one by one (a video frame 1.09x none's against
  // 1.04x). FSR2 asks the app for this gain (its pre-exposure); a layer measures it. false: round 15's.
  bool steadyGainCompensation = true;
  // Round 17 (the default, with steadyGainCompensation): the relit history is also taken where the box
  // admits the history as it was (texture, edges: a fade's first frames lag inside a wide box), but only
  // in a frame whose change the gain explains: over the probe's samples the change d (this frame's luma
  // less the history's) is one-signed for at least half its magnitude, |sum d| >= 1/2 sum |d|. A gain
  // moves every sample the same way (a fade: near 1); structure that moves (a video's zoom) and noise
  // move them both ways (near 0), so a video's drifting gain relights nothing. false: round 16's rule.
  bool steadyGainRelightsAdmitted = true;
  // Round 31 (the default, item 13; with steadyGainCompensation, whose probe sums it): a frame the pose does
  // not explain starts every pixel afresh, as a first frame. Over the probe's samples, the luma's mean over
  // 4x4-pixel blocks: where the frame's blocks differ from the history's (reprojected through the pose) by
  // more than they differ from their neighbours a block away (4 standard errors of the ratio above 1), the
  // history is misplaced by about a block or more as a whole. An app that turns its rig by a snap submits
  // the tracked head's pose, so the layer sees a still head under a picture that jumped; the box keeps what
  // of the misplaced history falls inside it, which a repeating texture makes likely (a snap over brick at
  // 90 Hz: frames up to 1.35x none's). Not where the gain explains the change (a fade) or the blocks' change
  // is under the box's floor (rounding). false: round 30's default.
  bool steadyUnexplainedFrameResets = true;
  // Round 42 (the default, item 14; with steadyGainCompensation or steadyNoiseEstimate, whose probe looks):
  // the filter switches itself to the profile hud's settings (withHudProfile) for the rest of the session
  // once its probe has found that the app draws head-locked content into its eye images (a HUD, a reticle).
  // Round 41's study built in (eval/head_locked_detector.h; filter_head_locked.h): in the frame where the
  // head's rotation has carried half of an eye's probe samples 2 px since the last such frame, a sample whose
  // 4x4 block still matches its block of then at the same pixel, and not where the world carried it,
  // testifies head-locked; 8 samples that testified so in 2 such frames and never for the world decide.
  // false: round 41's default.
  bool steadyHeadLockedSwitch = true;
  // Round 48 (the default, item 15): beside a geometric edge the app already resolved (its MSAA), the
  // frame as it is, where it has depth. A pixel whose luma is flat (within a code) behind it and along the
  // edge, whose neighbour across holds one mix of this pixel's colour and the colour two pixels across in
  // every channel (a coverage strictly between 1/8 and 7/8), whose far side is flat too, with the step over
  // 4 codes and 1/z not affine over the three pixels (a depth edge): there the app's image is already the
  // pixel's area average, so the history's resampling blur (item 3's budget) and item 4's leak across the
  // step are all error (round 47: every break of an MSAA app's promise sat in that ring). The pixel takes
  // this frame's sample wherever the history's tap moved. A 1-sample app has no such mixes at geometric
  // edges; a filtered texture does, but not across a depth edge. false: round 47's default.
  bool steadyResolvedEdges = true;
  // Round 20 (the default): the 8-bit output keeps the code it showed last frame (at the texel the
  // reprojection came from) while the filtered estimate lies within 1/2 + steadyOutputHold codes of it
  // and moved by less than half a code since last frame (round 21: in codes through the encoding's
  // slope at the estimate, to first order): a Schmitt trigger on the rounding. An estimate
  // that hovers at a code boundary (a smooth gradient or a photo under tremor: each frame's blend step
  // moves it by a fraction of a code) no longer flips the output back and forth; a flip is undone only
  // by a move of 2 x hold. A change of half a code a frame or more (a fade) is shown as rounding shows
  // it (held, 0.8 of a code a frame went in steps of two codes every other frame). The output is at
  // most 1/2 + hold codes from the estimate; the history keeps the unrounded estimate. The margin
  // shrinks linearly with how far the picture moved at the pixel since last frame, to 0 at half a
  // pixel (last frame's texel may then show a neighbour: a turn over a fine grating). 1/4 measured
  // beside 1/2, which let a fade lag a whole code (a 90 Hz fade frame 1.17x none's). 0 = plain
  // rounding. Only 8-bit outputs that steady's temporal pass writes (not those of the stereo pass).
  float steadyOutputHold = 0.25f;
  // The noise variance per linear RGB channel to use when steadyNoiseEstimate is off (0 = a clean
  // render: steady as before round 13). The eval tells it the scene's own (noisevar=-1).
  float steadyNoiseVariance = 0.0f;
  // inner: 1/3 - V_max/2 with V_max = 5/12, the blurriest static history (kappa's comment): 1/8.
  float steadyClipCurvatureInner = 1.0f / 8.0f;
  // Issue 14 round 8 (the default; round 7 measured it with an exact pow, off): the clip box's floor
  // (a flat 3x3 has sigma = 0 and c'' = 0) is half a step of the 8-bit sRGB input at the box mean's
  // luma L, not half a step in linear light: at L = 0.02 an sRGB step is 0.24/255, so the linear
  // floor admits a lag of four input steps where the light changes (the start of a fade up from
  // 15 %: 1.71x none's at 90 Hz on the astronaut; README item 8). The slope d linear / d code is
  // gamma 2's, 2 sqrt(L) (0.88-1.42x IEC 61966-2-1's over the codes; the stand-in the
  // footprint uses), never below sRGB's linear toe 1/12.92, so it costs a multiply and a max.
  // Applied only to sRGB input: UNORM input is filtered in its own codes (a linear step).
  bool steadyClipQuantSrgb = true;
  // Resampling-blur guard: a bilinear history tap at sub-pixel offset (fx, fy) adds fx(1-fx) +
  // fy(1-fy) px^2 of blur variance; alpha is raised so that the steady-state blur of the history,
  // (1 - alpha) / alpha times that, stays within steadyBlurBudgetPx2 (0 = off). 1/6 = 1/12 + 1/12,
  // the variance of the pixel's own one-pixel box footprint in x and y: the history may be no
  // blurrier than the pixel-area average it estimates. (Measured beside 1/4 and 1/2: README.)
  float steadyBlurBudgetPx2 = 1.0f / 6.0f;
  // The guard above per axis: the box's variance is 1/12 px^2 along x and along y, and a history
  // blurred by more along one axis is blurrier than the box there, whatever the other axis holds.
  // So the blurrier axis's blur, its f(1 - f), is counted for both. Summed over the axes instead, a
  // motion along one axis (sway, a pursuit, a lean) may blur that axis by the whole 1/6. Measured
  // on the corpus (README, the default): worst frame 1.09x none's against 1.17x summed (no case
  // above 1.10x against 2), mean RMSE 67.6 % of none's against 68.3 %, 97 cases at or below the
  // better taa against 93; thin geometry 69.7 % of none's against 68.0 %. Off: summed (ablation).
  bool steadyHistoryBlurPerAxis = true;
  // Issue 14 round 26 (with the guard per axis, where the render's noise s^2 per RGB channel is estimated
  // or told): the guard above gives way, per axis, to the alpha that minimises the steady-state error of
  // the exponential mean, its noise alpha/(2 - alpha) s_Y^2 plus the bias (B c''/2)^2 of a blur of
  // variance B = (1 - alpha)/alpha f(1 - f) on the luma's curvature c'': to first order in alpha,
  // alpha^3 = (f(1 - f) c'' / s_Y)^2. c'' is the 3x3's second difference with the noise's share (6 s_Y^2:
  // weights 1, -2, 1) taken out of its square; s_Y^2 = 3/8 s^2, the luma's share. The 3x3 vouches for
  // c'' within one pixel of the centre, so the blur's two standard deviations stay within it (B <= 1/4 px^2
  // per axis), and the alpha is never above the guard's. A clean render (s = 0) keeps the guard.
  // Measured: README item 12 (all-noisy held-out draws 2-3 % lower RMSE; the content grid unchanged).
  bool steadyBlurNoiseTrade = true;
  // The current frame's estimate of the pixel's area average (the ground truth of a pixel; a
  // lone centre sample aliases): its 3x3 through [k, 1 - 2k, k] per axis. k = 1/24 gives the
  // filter the second moment of the pixel's own box footprint, 2k = 1/12 px^2 (the box average of
  // a smooth signal is f + f''/24). 0 = off (ablation).
  float steadyFootprint = 1.0f / 24.0f;
  // The footprint filter weighs square roots of the linear-light taps and squares the result. Its
  // f''/24 term holds for a signal smooth over a pixel; at an edge it leaks k of the step into
  // the neighbour, and a linear-light leak from a bright side into a dark one is magnified by the
  // display encoding's slope near black (sRGB: 12.92, against about 1.1 at mid grey), which is
  // what the eye (and the eval's metric) sees. In the square root (gamma 2, the cheap stand-in for
  // sRGB's about 2.2) the leak is k of the step as displayed. On a smooth signal both agree to
  // second order. Measured on the corpus (README, the default): the worst frame 1.17x none's
  // against 1.36x in linear light (a dark picture's border), 2 cases with a frame above 1.10x
  // against 4, mean RMSE unchanged; thin dark lines lose about 7 %. Off: linear light (ablation).
  bool steadyFootprintEncoded = true;
  // With jittered input (jitteredInput / ViewFrame::jitterPx) the current frame's taps are point
  // samples at the jitter's offset from their pixel centres; steady does not resample them
  // bilinearly (that blurs: default+jitter was 91.7 % of none's RMSE on an 85-case corpus slice,
  // 73.8 % now) but weighs the 3x3 per axis so that its moments about the pixel centre are the
  // footprint's (sum w x = 0, sum w x^2 = 2k), and its clip box's (2/3). false: the sample inside
  // the pixel alone (over the jitter's cycle, uniform over the pixel, its running mean converges
  // to the box average, Karis 2014), measured worse on the corpus: 89.0 % of none's against 76.9 %.
  bool steadyJitterRecentred = true;
  // The nearest distance of content (0.75 m: the near end of the comfortable range, 0.75-3.5 m, in
  // Oculus' VR best practices). Used by the stereo pass without depth: the disparity is the far
  // plane's, the true one lies anywhere up to this distance (its spread; over a pixel, no blend).
  // Round 8 removed its use in steady's blur guard (the reprojection's parallax spread without
  // depth counted as blur): it did not measurably help on the corpus (0.702 against 0.703 of
  // none's without it, nothing at 90 Hz or 20 ppd; round 7 run): RMSE was higher with it in 16 of
  // the 19 cases it moved by over 0.3 % (the disocclusion scene without depth in all 10).
  float steadyNearestDepthM = 0.75f;
  bool steadyInterpolated = false;  // ablation: seed 003's reprojection to the pose at sampleD[0]

  // stereo (seed 002 §4.1, §5.2)
  float stereoFarDistanceM = 10.0f;    // assumed scene distance when no depth is given
  float stereoDepthTolerance = 0.05f;  // relative depth difference that rejects the other eye
  // Lower clamp of beta (the weight of this eye). The other eye is a sample as noisy as this
  // one, so it should never outweigh it (beta >= 0.5). 0.9 measured (eval, 256x256): 0.7 pulls
  // the eyes of the thin-geometry scene closer together than ground truth's are (stereo gap
  // +177 %, RMSE +0.6 %); 0.9 brings every scenario's stereo difference closer to ground truth's.
  float stereoBetaMin = 0.9f;
  // After steady: beta from the two eyes' error variances instead of Eq. 4 (stereo.comp). Each
  // eye's estimate of the pixel's area average errs like a sample displaced over the pixel's own
  // box (1/6 px^2) divided by its sample count; the other eye's reprojected estimate adds its
  // bilinear tap's f(1-f) px^2 per axis and, without depth, the disparity's spread. Inverse-variance
  // weights: beta = var_other / (var_this + var_other). The seed methods keep Eq. 4.
  bool stereoInverseVariance = true;
  // After steady, with the inverse-variance beta: the other eye's bilinear tap at offset f is
  // c(q) + (1/2) f(1-f) c'' per axis (Taylor), a blur of the very kind steady's own error has; the
  // curvature term is taken off with this eye's second differences (the same surface, by the depth
  // check). Without it the tap's blur made up about 70 % of the truth's own inter-eye difference
  // on the image viewer (README, the default: stereo).
  bool stereoTapCurvature = true;
  // After steady, with the inverse-variance beta: the other eye is clipped to this eye's 3x3 box
  // mean +- gamma sigma with this gamma, not taa's 1. Both eyes are of the same instant, so the box
  // guards only against a surface the depth check missed; a tap of the same surface interpolates
  // this eye's neighbours, which lie within sqrt(9 - 1) sigma of their mean (Samuelson's bound for
  // nine values). Narrower boxes pull a correct sample towards the local mean, a blur (README).
  float stereoClipGammaAfterSteady = 2.8284271f;  // sqrt(8)

  HistoryFilter historyFilter = HistoryFilter::Bilinear;
  HistoryFormat historyFormat = HistoryFormat::Rgba16f;

  // The caller jitters the render (ViewFrame::jitterPx): every frame, also one with a jitter of 0,
  // goes through the un-jittering fetch (bilinear at c - jitter; at 0 it reads the texel exactly),
  // so the pipeline does not change, and recompile, when the jitter starts.
  bool jitteredInput = false;

  // Pixels per shader invocation in every pass but fxaa: Auto picks 4x4 on a CPU device
  // (lavapipe; shared 3x3 neighbourhood fetches, and faster even where none are shared) and 1x1
  // on a GPU (coalesced accesses).
  InvocationBlock invocationBlock = InvocationBlock::Auto;

  // history reset
  float resetAngleDeg = 30.0f;  // a pose jump larger than this between frames resets history
  float resetTranslationM = 0.5f;
};

std::string_view toString(TemporalMethod m);
std::optional<TemporalMethod> parseTemporalMethod(std::string_view name);

// Full method names as users type them: "none", "fxaa", "taa", "hmtaa", "vtaa", "hybrid",
// "stereo" (stereo only), "<temporal>+stereo", and "default". Returns nullopt for unknown names.
// Only the method fields of `base` are changed.
std::optional<Params> applyMethodName(std::string_view name, Params base = {});
std::string methodName(const Params& p);  // inverse of applyMethodName

// Checks ranges (NaN, negative, out of [0,1], ...). Returns an empty string when valid, else a
// human-readable message naming the first bad field; `sanitized` gets safe defaults for bad fields.
std::string validate(const Params& p, Params* sanitized = nullptr);

// The profile hud (README, "An app that draws its HUD into the eye images"; the layer's config names it
// `profile = hud`) over `p`: item 3's blur budget at a tenth of a pixel's spread (round 11: the budget
// across an edge that does not move with the world is what rings around a HUD) and a clip box that reaches
// out to the frame's own estimate.
inline constexpr float kHudBlurBudgetPx2 = 0.0104f;
Params withHudProfile(Params p);

}  // namespace steadyxr::core
