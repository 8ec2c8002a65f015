// The dynamic-resolution study (render_size_study.h): per case, the app's frames at the fixed size and
// at the changing sizes, each method at each, RMSE against the ground truth at the frame's own size.
#include "render_size_study.h"

#include "eye_rig.h"
#include "frame_clock.h"
#include "image.h"
#include "locomotion.h"
#include "metrics.h"
#include "progress.h"
#include "renderer.h"
#include "results.h"
#include "scenario_list.h"
#include "scene.h"
#include "variants.h"

#include "steadyxr/core/filter.h"
#include "steadyxr/core/vulkan_context.h"
#include "steadyxr/imu/motion.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

namespace steadyxr::eval {

namespace {

// How a method meets the changing sizes: not at all (the full size every frame), keeping its history,
// or dropping it at each change.
enum class Mode { Fixed, Kept, Dropped };
constexpr std::array<Mode, 3> kModes{Mode::Fixed, Mode::Kept, Mode::Dropped};
const char* nameOf(Mode m) {
  return m == Mode::Fixed ? "fixed" : m == Mode::Kept ? "changing" : "changing-dropped";
}

// One method run one way: its filter (its own history), this case's per-frame RMSE and temporal error
// (from the second frame), and last frame's output and truth per eye as shown (at the full size).
struct Run {
  std::string method;
  Mode mode;
  std::unique_ptr<core::Filter> filter;
  std::vector<double> rmse, temporalError;
  std::array<Image, 2> previousOut, previousTruth;
};

// What a mode's figures are summed into over the cases; shimmer over the low-head-speed cases only,
// as the suite's shimmer target.
struct Totals {
  double ratioSum = 0.0;
  int cases = 0, casesAboveNone = 0, framesAbove110 = 0;
  double worstFrame = 0.0;
  double shimmerRatioSum = 0.0;
  int lowSpeedCases = 0, shimmerAboveNone = 0;
};

double average(const std::vector<double>& v) {
  double sum = 0.0;
  for (double x : v) sum += x;
  return v.empty() ? 0.0 : sum / double(v.size());
}

}  // namespace

int runRenderSizeStudy(const Options& o) {
  std::string error;
  std::vector<Scenario> scenarios;
  TextureSet textures;
  if (!loadCases(o, &scenarios, &textures, &error)) {
    std::cerr << "steadyxr-eval: " << error << "\n";
    return 2;
  }
  auto ctx = createEvalContext(o, &error);  // first: it outlives every filter and renderer below
  if (!ctx) {
    std::cerr << "steadyxr-eval: no Vulkan context: " << error << "\n";
    return 1;
  }
  // One renderer per size (its own eye targets and output images): the filter sees the app's image
  // change size, as it would see the rect. The full size is the first.
  std::vector<std::pair<int, int>> sizes{{o.width, o.height}};
  std::vector<int> sizeOfFrame;  // index into sizes, one per entry of o.renderSizes
  for (double fraction : o.renderSizes) {
    const std::pair<int, int> s{std::max(16, int(std::lround(o.width * fraction))),
                                std::max(16, int(std::lround(o.height * fraction)))};
    auto at = std::find(sizes.begin(), sizes.end(), s);
    if (at == sizes.end()) at = sizes.insert(sizes.end(), s);
    sizeOfFrame.push_back(int(at - sizes.begin()));
  }
  RenderOptions renderOptions;
  renderOptions.srgb = !o.unorm;
  renderOptions.mipmaps = o.mipmaps;
  std::vector<std::unique_ptr<SceneRenderer>> renderers;
  for (const auto& [w, h] : sizes) {
    renderers.push_back(SceneRenderer::create(*ctx, w, h, textures.images, renderOptions, &error));
    if (!renderers.back()) {
      std::cerr << "steadyxr-eval: renderer: " << error << "\n";
      return 1;
    }
  }
  const std::vector<std::string> methods =
      !o.methods.empty() ? o.methods : std::vector<std::string>{"none", "taa", "default"};
  if (std::find(methods.begin(), methods.end(), "none") == methods.end()) {
    std::cerr << "steadyxr-eval: --render-sizes scores every method against none: add it to --methods\n";
    return 2;
  }
  std::vector<Run> runs;
  for (const std::string& m : methods) {
    for (Mode mode : kModes) {
      if (m == "none" && mode == Mode::Dropped) continue;  // nothing to drop
      Variant v;
      if (!parseVariant(m, &v, &error)) {
        std::cerr << "steadyxr-eval: " << error << "\n";
        return 2;
      }
      if (v.source != 1 || v.jitter || v.oracle) {
        std::cerr
            << "steadyxr-eval: --render-sizes takes methods on the 1-sample render without jitter, not '" << m
            << "'\n";
        return 2;
      }
      Run r{m, mode, core::Filter::create(*ctx, v.params, &error), {}, {}, {}, {}};
      if (!r.filter) {
        std::cerr << "steadyxr-eval: filter '" << m << "': " << error << "\n";
        return 1;
      }
      runs.push_back(std::move(r));
    }
  }
  std::filesystem::create_directories(o.outDir);
  std::ofstream csv(o.outDir + "/render_sizes.csv");
  csv << "scenario,method,mode,rmse,rmse_vs_none,worst_frame_vs_none,frames_above_1_10,temporal_error,"
         "temporal_error_vs_none,low_speed\n";
  std::vector<Totals> totals(runs.size());
  const double dt = 1.0 / o.appHz;
  Progress progress(o.progress, int(scenarios.size()) * o.frames);
  int framesDone = 0;

  for (const Scenario& sc : scenarios) {
    CaseMotion motion;
    if (!loadMotion(sc, o, &motion, &error)) {
      std::cerr << "steadyxr-eval: " << error << "\n";
      return 2;
    }
    const std::unique_ptr<imu::MotionStream>& stream = motion.stream;
    const double firstFrameSec = motion.firstFrameSec;
    const FrameClock clock(o.frames, firstFrameSec, dt, o.dropFrames, o.seed);
    Scene scene;
    if (!makeScene(sc.scene, sc.picture, textures, 1.0, HeadPose{}, &scene, &error)) {
      std::cerr << "steadyxr-eval: " << error << "\n";
      return 2;
    }
    if (stream->validUntilSec() < clock.lastSec()) {
      std::cerr << "steadyxr-eval: motion '" << sc.motion << "' ends before the run does\n";
      return 2;
    }
    // As the suite: the layer is told the tracked head; the app renders from its rig on top.
    auto trackedAt = [&](double t) {
      const imu::MotionState m = stream->at(std::max(0.0, t));
      return HeadPose{glm::normalize(m.orientation), m.position + scene.headOffset(t)};
    };
    const RigSchedule rig{double(clock.periodOf(o.frames - 1)) * dt, trackedAt(firstFrameSec), 1.0};
    for (Run& r : runs) {
      r.filter->reset();
      r.rmse.clear();
      r.temporalError.clear();
      r.previousOut = r.previousTruth = {};
    }
    std::vector<double> headSpeeds;
    for (int f = 0; f < o.frames; ++f) {
      const double t = clock.timeOf(f);
      const HeadPose tracked = trackedAt(t);
      const HeadPose head = rigPose(o.locomotion, rig, tracked, t - firstFrameSec);
      const float headSpeed = float(stream->headSpeedDegPerSec(std::max(0.0, t)));
      headSpeeds.push_back(headSpeed);
      const int changing = sizeOfFrame[size_t(f) % sizeOfFrame.size()];
      const int changedFrom = f > 0 ? sizeOfFrame[size_t(f - 1) % sizeOfFrame.size()] : changing;
      // The app's frame and the truth at each size this frame uses: the full size, the changing one.
      std::vector<std::array<Image, 2>> truth(sizes.size());
      for (int s : {0, changing}) {
        if (!truth[size_t(s)][0].empty()) continue;
        const auto cams = eyeCameras(head, sizes[size_t(s)].first, sizes[size_t(s)].second, EyeRig{});
        for (int eye = 0; eye < 2; ++eye) {
          DrawList draws = scene.drawsAt(t, head);
          draws.noiseSeed = uint32_t(f * 2 + eye + 1);
          if (o.noise > 0.0f) draws.noiseAmplitude = o.noise;
          RenderedView base;
          if (!renderers[size_t(s)]->renderBase(eye, cams[eye], draws, &base, nullptr, &error) ||
              !renderers[size_t(s)]->renderGroundTruth(cams[eye], draws, o.gtGrid, &truth[size_t(s)][eye],
                                                       &error)) {
            std::cerr << "steadyxr-eval: render: " << error << "\n";
            return 1;
          }
        }
      }
      for (Run& r : runs) {
        const int s = r.mode == Mode::Fixed ? 0 : changing;
        SceneRenderer& renderer = *renderers[size_t(s)];
        const auto [w, h] = sizes[size_t(s)];
        const auto cams = eyeCameras(head, w, h, EyeRig{});
        const auto trackedCams = eyeCameras(tracked, w, h, EyeRig{});
        core::StereoFrame frame;
        frame.viewCount = 2;
        for (int eye = 0; eye < 2; ++eye) {
          core::ViewFrame& view = frame.views[eye];
          view.color = renderer.baseColor(eye);
          if (sc.depthGiven) view.depth = renderer.baseDepth(eye, cams[eye].nearZ, cams[eye].farZ);
          view.pose = trackedCams[eye].pose;
          view.fov = cams[eye].fov;
        }
        frame.displayTimeNs = int64_t(std::llround((t + sc.leadSec + 1.0) * 1e9));
        frame.headSpeedDegPerSec = headSpeed;
        frame.reset = f == 0 || (r.mode == Mode::Dropped && changing != changedFrom);
        core::StereoOutput output;
        output.views = {renderer.output(0), renderer.output(1)};
        const bool ok = r.filter->submit(frame, output, &error);
        r.filter->waitIdle();
        if (!ok) {
          std::cerr << "steadyxr-eval: filter '" << r.method << "' submit failed: " << error << "\n";
          return 1;
        }
        double sum = 0.0, change = 0.0;
        for (int eye = 0; eye < 2; ++eye) {
          Image out;
          if (!renderer.readOutput(eye, &out, &error)) {
            std::cerr << "steadyxr-eval: readback: " << error << "\n";
            return 1;
          }
          const Image& gt = truth[size_t(s)][eye];
          sum += rmse(out, gt) / 2.0;
          // The suite's temporal error (the output's change against the truth's) on the display's grid:
          // each frame's output and truth upscaled to the full size, as the compositor shows the rect (the
          // identity at the full size, where it is the suite's figure to the bit).
          Image shown = resampled(out, o.width, o.height), shownTruth = resampled(gt, o.width, o.height);
          if (!r.previousOut[eye].empty())
            change += 255.0 *
                      temporalErrorVsTruth(r.previousOut[eye], shown, r.previousTruth[eye], shownTruth) / 2.0;
          r.previousOut[eye] = std::move(shown);
          r.previousTruth[eye] = std::move(shownTruth);
        }
        r.rmse.push_back(sum);
        if (f > 0) r.temporalError.push_back(change);
      }
      progress.update(++framesDone, sc.label);
    }
    // Each run against none's at the same sizes (the fixed ones against none's fixed), frame by frame.
    const bool lowSpeed = percentile(headSpeeds, 0.95) < kLowSpeedDegPerSec && !rigMoves(o.locomotion);
    for (size_t i = 0; i < runs.size(); ++i) {
      const Run& r = runs[i];
      const Mode noneMode = r.mode == Mode::Fixed ? Mode::Fixed : Mode::Kept;
      const auto none = std::find_if(runs.begin(), runs.end(),
                                     [&](const Run& n) { return n.method == "none" && n.mode == noneMode; });
      double mean = 0.0, noneMean = 0.0;
      for (size_t f = 0; f < r.rmse.size(); ++f) {
        mean += r.rmse[f] / double(r.rmse.size());
        noneMean += none->rmse[f] / double(r.rmse.size());
      }
      const Ghosting g = ghostingPerFrame(r.rmse, none->rmse, {});
      int above = 0;
      for (size_t f = 0; f < r.rmse.size(); ++f)
        above += r.rmse[f] > 1.10 * std::max(none->rmse[f], kEightBitRmseFloor);
      const double ratio = mean / std::max(noneMean, kEightBitRmseFloor);
      const double shimmer = average(r.temporalError);
      const double shimmerRatio = shimmer / std::max(average(none->temporalError), 1e-9);
      csv << sc.label << ',' << r.method << ',' << nameOf(r.mode) << ',' << mean << ',' << ratio << ','
          << g.worstRatio << ',' << above << ',' << shimmer << ',' << shimmerRatio << ',' << lowSpeed << '\n';
      Totals& tt = totals[i];
      if (lowSpeed) {
        tt.shimmerRatioSum += shimmerRatio;
        tt.lowSpeedCases += 1;
        tt.shimmerAboveNone += shimmerRatio > 1.0;
      }
      tt.ratioSum += ratio;
      tt.cases += 1;
      tt.casesAboveNone += ratio > 1.0;
      tt.framesAbove110 += above;
      tt.worstFrame = std::max(tt.worstFrame, g.worstRatio);
    }
  }
  progress.update(framesDone, "done");
  std::fprintf(stderr, "\n");
  std::printf("render sizes (fractions of %dx%d, one a frame in turn):", o.width, o.height);
  for (double fraction : o.renderSizes) std::printf(" %.3g", fraction);
  std::printf("\n%-24s %-17s %14s %16s %18s %12s %17s %12s\n", "method", "sizes", "RMSE / none's",
              "cases above none", "frames above 1.10x", "worst frame", "shimmer / none's", "above none");
  for (size_t i = 0; i < runs.size(); ++i) {
    const Totals& tt = totals[i];
    std::printf("%-24s %-17s %14.3f %16d %18d %11.2fx %17.3f %12d\n", runs[i].method.c_str(),
                nameOf(runs[i].mode), tt.ratioSum / std::max(tt.cases, 1), tt.casesAboveNone,
                tt.framesAbove110, tt.worstFrame, tt.shimmerRatioSum / std::max(tt.lowSpeedCases, 1),
                tt.shimmerAboveNone);
  }
  std::printf(
      "(mean over %zu cases of each case's mean RMSE over none's at the same sizes; frames: each frame's "
      "RMSE over none's in that frame; shimmer: the temporal error against the truth over none's at the same "
      "sizes on the full size's grid, mean over the %d cases with head speed p95 < %.0f deg/s)\nOutputs: "
      "%s/render_sizes.csv\n",
      scenarios.size(), totals.empty() ? 0 : totals[0].lowSpeedCases, kLowSpeedDegPerSec, o.outDir.c_str());
  return 0;
}

}  // namespace steadyxr::eval
