// steadyxr-eval: the evaluation harness's command line (see suite.h and DESIGN.md "Evaluation").
#include "eye_rig.h"
#include "render_size_study.h"
#include "suite.h"

#include <cstdlib>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

namespace {

std::vector<std::string> splitList(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, ',');) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

void usage() {
  std::cout <<
      R"(usage: steadyxr-eval [options]
Renders test scenes under simulated head motion, filters them with every method of the filter
core, models the display stage (timewarp, seed 004 depth warping) and prints accuracy and cost.

  --out DIR            output folder (default out)
  --scenes LIST        imageviewer,thin,moving,disocclusion,noisy (default: the default suite);
                       content that changes in place on the image viewer: video, fade, blink;
                       hud: the image viewer plus a head-locked reticle and text panel
                       (per-frame RMSE on its pixels in overlay.csv, eval/overlay_report.py)
  --motions LIST       head-motion presets (steadyxr-imu-emu --list-motions; e.g. tremor-1x,
                       microsaccades,sway,pursuit-hold,pursuit-stop-pursuit,fastturn,walk,lean,
                       fixation,pursuit,sequence)
  --trace FILE[,FILE]  head-motion trace CSV(s) (t_s,qw,qx,qy,qz[,...] or t_s,wx,wy,wz); repeatable
  --images LIST        pictures for the image viewer: PNG paths, python3-skimage names
                       (astronaut, camera, coffee, brick, grass, gravel, text, ...) or the
                       procedural zoneplate, lines1px, hatch, smalltext, darkgradient (default
                       astronaut,camera,...: the default suite uses the first two and zoneplate
                       under fixation, every given one otherwise); a picture that does not
                       load as PNG stops the run (python3-skimage's JPEGs: convert them first)
  --pictures-dir DIR   where built-in picture names are found (default python3-skimage's data)
  --methods LIST       none,fxaa,msaa2,msaa4,taa,hmtaa,vtaa,hybrid, each also <m>+stereo,
                       stereo, default; the temporal ones and default also <m>+jitter (the
                       layer's Halton(2,3) jitter, undone through ViewFrame::jitterPx); oracle
                       (static scenes: exact reprojection, 1/N over 16 frames, on the CPU;
                       the unjittered frames) and oracle+jitter (the jittered frames);
                       sweeps as <m>@key=value[@key=value] with keys
                       hmax,wmin,wlb,amin,alpha,gamma,beta,ivbeta,tapcurv,sclip,d,catmull and steady's
                       floor,conf,reject,boxcur,curvbox,curvkappa,clip,blur,footprint,fpenc,
                       bluraxis,near,interp,jrecentre (jittered input), curvcentre,
                       curvinner,quantsrgb (rounds 7-8: content changes), curvgate (round 10),
                       noiseest=0 (no noise estimate: the default before round 15), noisetime=0 (round 13's, the
                       frame's own detail alone), noisechange=0 (round 14's, no
                       test for a change as a whole), gain=0 (round 15's: no gain
                       compensation), gainall=0 (round 16's: the relit history
                       only where the box rejects the history), cut=0 (round 30's: no
                       fresh start where the pose does not explain a frame), resolved=0 (round 47's:
                       no item 15, the frame beside an edge the app resolved), noisevar=V (a noise variance
                       told instead; -1: the scene's own), history=16|8
                       (the history's bits per channel) and dither=0|1 after history=8;
                       autohud=1 (round 41's study: the profile hud from the frame after
                       eval/head_locked_detector.h finds head-locked content; autohud.csv)
                       (default: all + sweeps)
  --corpus             every motion preset over the corpus pictures and scenes, translating
                       motions with and without depth; one table per motion and picture
                       class (defaults: 96x96, 48 frames placed over the preset's motion
                       changes, display = app rate, no seed 004
                       study, fewer methods; ~5 min on 2 cores); --motions, --images and
                       --scenes (imageviewer, thin, moving, disocclusion) narrow it; --scenes
                       hud adds the head-locked overlay over every corpus picture
  --unorm              UNORM eye images and textures (filtering in encoded values) instead
                       of sRGB (linear light, the default)
  --no-mipmaps         sample textures without mipmaps (the worst case; default trilinear)
  --animate CASE       write the animated comparison frames of this case (default: the first
                       case; plot.py makes out/anim/CASE.gif)
  --write-frames N     every Nth frame of every case: the left eye's truth and each method's
                       output as 8-bit PNGs, out/frames/CASE/{gt,METHOD}_FRAME.png (for analyses
                       outside the harness, e.g. docs/experiments/round26-footprint-k.py)
  --resolution WxH     per eye (default 256x256)
  --frames N           app frames per scenario (default 40)
  --seed N             head-motion seed (default 1)
  --app-hz F           app frame rate (default 30)
  --display-hz F       display rate (default 90)
  --start S            start time in the motion stream, seconds (default 0)
  --gt-grid N          ground truth with N*N samples per pixel, N-rooks (default 8 = 64 spp: the
                       corpus's figures agree with N = 16's to 0.016 of none's RMSE, round 19)
  --warp-steps N       seed 004 study: extrapolate 1..N display frames (default 6)
  --threshold F        error-pixel threshold per channel in [0,1] (default 0.1)
  --noise F            add per-frame noise of amplitude F to every scene (the "noisy" scene is
                       the image viewer with 0.08)
  --ppd F              a headset's pixel density: narrow each eye's fov (its tangents scaled, its
                       shape kept) to F pixels per degree at the centre (Quest 2 ~20, Index
                       ~14; default off: ~0.85 at 96 px, the wide fov squeezed into few pixels),
                       so head motion moves the image by as many pixels as on a headset; the
                       image viewer's picture moves further away and the scenes in metres are
                       stretched in depth to keep their pixels; a scene that would pass the far
                       plane is refused (--corpus leaves it out)
  --cant DEG           canted displays: each eye's view yawed outwards by DEG (0-20; the Pimax
                       5k+'s native views: 10), rendered and submitted so, as such a headset's
                       runtime reports its views; with --ppd each eye's crop is the part of its
                       view around the head's straight ahead (an off-axis frustum), which both
                       eyes see
  --app-msaa N         the app renders its eye images with N x MSAA (2 or 4), resolved, as most VR
                       apps do: every method takes the resolved image as the app's (none is it;
                       depth is the 1-sample render's, as an app that resolves depth from one sample)
  --locomotion KIND:N  the app's own rig motion, which it renders but does not submit (OpenXR
                       poses are the tracked head's): the layer sees the head, the picture moves
                       by both. turn:DEG_PER_S (a smooth turn, left for > 0), strafe:M_PER_S,
                       forward:M_PER_S (a stick held for the middle half of the run), snap:DEG
                       (a snap turn at a third of the run and back at two thirds); such cases are
                       never low-speed ones; the display stage's extra frames (display rate above
                       the app's) warp with the rigged poses, as a runtime that knew the rig
  --render-sizes LIST  dynamic resolution, a study in place of the suite: the app renders frame f at
                       fraction LIST[f mod n] of the eye size (0.25-1, e.g. 1,0.9,0.8,0.9); every
                       method (default none,taa,default) at the fixed size, at the changing sizes
                       keeping its history, and dropping it at each change, against none at the
                       same sizes (render_sizes.csv)
  --drop-frames P       the app misses each app period after a frame with probability P (0-0.5;
                       at most 3 in a row, drawn from --seed, the same for every case): its next
                       frame is for the period after, so the layer sees a pose step of two
                       periods or more, and video and moving objects step as far; truth and
                       inputs follow (eval/frame_clock.h); the display stage still shows each
                       frame for the display frames of one app period
  --no-sweeps          skip the parameter sweeps
  --quick              small run: 1 picture, no sweeps, 16 frames, 96x96 (unless given)
  --validation         enable the Vulkan validation layer
  --no-progress        no progress bar
)";
}

}  // namespace

int main(int argc, char** argv) {
  steadyxr::eval::Options o;
  bool resolutionGiven = false, framesGiven = false, displayGiven = false, warpGiven = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "steadyxr-eval: " << a << " needs a value\n";
        std::exit(2);
      }
      return argv[++i];
    };
    try {
      if (a == "--help" || a == "-h") {
        usage();
        return 0;
      } else if (a == "--out") {
        o.outDir = next();
      } else if (a == "--scenes" || a == "--scene") {
        o.scenes = splitList(next());
      } else if (a == "--motions" || a == "--motion") {
        o.motions = splitList(next());
      } else if (a == "--trace" || a == "--traces") {
        for (const auto& t : splitList(next())) o.traces.push_back(t);
      } else if (a == "--pictures-dir") {
        o.picturesDir = next();
      } else if (a == "--images" || a == "--image") {
        o.images = splitList(next());
      } else if (a == "--methods") {
        o.methods = splitList(next());
      } else if (a == "--resolution") {
        const std::string r = next();
        const auto x = r.find('x');
        o.width = std::stoi(r.substr(0, x));
        o.height = x == std::string::npos ? o.width : std::stoi(r.substr(x + 1));
        resolutionGiven = true;
      } else if (a == "--frames") {
        o.frames = std::stoi(next());
        framesGiven = true;
      } else if (a == "--seed") {
        o.seed = std::stoull(next());
      } else if (a == "--app-hz") {
        o.appHz = std::stod(next());
      } else if (a == "--display-hz") {
        o.displayHz = std::stod(next());
        displayGiven = true;
      } else if (a == "--start") {
        o.startSec = std::stod(next());
      } else if (a == "--gt-grid") {
        o.gtGrid = std::stoi(next());
      } else if (a == "--warp-steps") {
        o.warpSteps = std::stoi(next());
        warpGiven = true;
      } else if (a == "--threshold") {
        o.errorThreshold = std::stof(next());
      } else if (a == "--noise") {
        o.noise = std::stof(next());
      } else if (a == "--corpus") {
        o.corpus = true;
      } else if (a == "--unorm") {
        o.unorm = true;
      } else if (a == "--no-mipmaps") {
        o.mipmaps = false;
      } else if (a == "--animate") {
        o.animate = next();
      } else if (a == "--write-frames") {
        o.writeFramesEvery = std::stoi(next());
        if (o.writeFramesEvery < 1) throw std::invalid_argument("write-frames");
      } else if (a == "--ppd") {
        o.ppd = std::stod(next());
        if (!(o.ppd > 0.0)) throw std::invalid_argument("ppd");
      } else if (a == "--cant") {
        o.cantDeg = std::stod(next());
        if (!(o.cantDeg >= 0.0 && o.cantDeg <= 20.0)) throw std::invalid_argument("cant");
      } else if (a == "--app-msaa") {
        o.appMsaa = std::stoi(next());
        if (o.appMsaa != 2 && o.appMsaa != 4) throw std::invalid_argument("app-msaa");
      } else if (a == "--locomotion") {
        std::string error;
        if (!steadyxr::eval::parseLocomotion(next(), &o.locomotion, &error)) {
          std::cerr << "steadyxr-eval: " << error << "\n";
          return 2;
        }
      } else if (a == "--drop-frames") {
        o.dropFrames = std::stod(next());
        if (!(o.dropFrames >= 0.0 && o.dropFrames <= 0.5)) {
          std::cerr << "steadyxr-eval: --drop-frames takes the share of app frames missed, from 0 to 0.5\n";
          return 2;
        }
      } else if (a == "--render-sizes") {
        for (const std::string& f : splitList(next())) {
          o.renderSizes.push_back(std::stod(f));
          if (!(o.renderSizes.back() >= 0.25 && o.renderSizes.back() <= 1.0)) {
            std::cerr << "steadyxr-eval: --render-sizes takes fractions of the eye size from 0.25 to 1\n";
            return 2;
          }
        }
        if (o.renderSizes.empty()) throw std::invalid_argument("render-sizes");
      } else if (a == "--no-sweeps") {
        o.sweeps = false;
      } else if (a == "--quick") {
        o.quick = true;
      } else if (a == "--validation") {
        o.validation = true;
      } else if (a == "--no-progress") {
        o.progress = false;
      } else {
        std::cerr << "steadyxr-eval: unknown option '" << a << "' (see --help)\n";
        return 2;
      }
    } catch (const std::exception&) {
      std::cerr << "steadyxr-eval: bad value for " << a << "\n";
      return 2;
    }
  }
  if (o.quick) {
    if (!resolutionGiven) o.width = o.height = 96;
    if (!framesGiven) o.frames = 16;
  }
  if (o.corpus) {
    // Sized to stay well within 10 minutes on 2 cores: 120 cases took 5 min 10 s with the 16-spp truth
    // (docs/evaluation-corpus.md); round 19's 64 spp add about 0.7 s a case (1.9 s against 1.2 s, 3 methods).
    if (!resolutionGiven) o.width = o.height = 96;
    if (!framesGiven) o.frames = 48;
    if (!displayGiven) o.displayHz = o.appHz;  // the display stage's extra ground truths cost 3x
    if (!warpGiven) o.warpSteps = 0;
  }
  if (o.width < 16 || o.height < 16 || o.width > 4096 || o.height > 4096 || o.frames < 2 || o.gtGrid < 1 ||
      o.appHz <= 0 || o.displayHz < o.appHz || o.warpSteps < 0) {
    std::cerr
        << "steadyxr-eval: bad resolution/frames/rates (need >= 16x16, >= 2 frames, display >= app rate)\n";
    return 2;
  }
  // The picture moves to 1.5 m / tangent scale (scene.cpp, picturePlane): keep it inside the far plane.
  if (o.ppd > 0.0 && 1.5 / steadyxr::eval::ppdTangentScale(o.ppd, o.width) > 0.9 * steadyxr::eval::kFarZ) {
    std::cerr << "steadyxr-eval: --ppd " << o.ppd << " at " << o.width
              << " px puts the picture beyond the far plane (fewer ppd or more pixels)\n";
    return 2;
  }
  if (!o.renderSizes.empty()) {
    if (o.ppd > 0.0 || o.cantDeg > 0.0 || o.appMsaa > 1) {
      std::cerr
          << "steadyxr-eval: --render-sizes keeps the eye's fov and one sample: leave out --ppd, --cant and "
             "--app-msaa\n";
      return 2;
    }
    return steadyxr::eval::runRenderSizeStudy(o);
  }
  return steadyxr::eval::runSuite(o);
}
