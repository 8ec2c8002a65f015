#include "results.h"

#include "frame_clock.h"
#include "suite.h"

#include "steadyxr/core/params.h"

#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

namespace steadyxr::eval {

namespace {

std::string jsonStr(const std::string& s) {
  std::string o = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    o += c;
  }
  return o + "\"";
}

const char* boolStr(bool b) {
  return b ? "true" : "false";
}

}  // namespace

std::string fmt(double v, int prec) {
  std::ostringstream os;
  os << std::setprecision(prec) << v;
  return os.str();
}

std::string csvEscape(const std::string& s) {
  return s.find(',') == std::string::npos ? s : "\"" + s + "\"";
}

const ResultRow* findRow(const std::vector<ResultRow>& rows, const std::string& scenario,
                         const std::string& method) {
  for (const ResultRow& r : rows) {
    if (r.scenario == scenario && r.method == method) return &r;
  }
  return nullptr;
}

void writeResultsCsv(const std::string& path, const std::vector<ResultRow>& rows) {
  std::ofstream f(path);
  f << "scenario,scene,motion,picture,motion_class,picture_class,method,filter_method,sweep,stereo,jitter,"
       "depth_given,samples,mtcd,temporal_error,mtcd_display,rmse,ssim,rmse_display,error_pixels_display_pct,"
       "stereo_error,stereo_diff,stereo_diff_gt,stereo_gap,ghost_worst_ratio,ghost_worst_frame,recovery_"
       "frames,"
       "recovered,motion_changes,head_speed_p95,low_speed,static_scene,gpu_ms,gpu_temporal_ms,gpu_stereo_ms,"
       "gpu_other_ms,render_ms,cost_ms,cpu_us,temporal_error_truth8\n";
  for (const ResultRow& r : rows) {
    f << csvEscape(r.scenario) << ',' << r.scene << ',' << csvEscape(r.motion) << ',' << r.picture << ','
      << r.motionClass << ',' << r.pictureClass << ',' << r.method << ',' << r.filterMethod << ',' << r.sweep
      << ',' << r.stereo << ',' << r.jitter << ',' << r.depthGiven << ',' << r.source << ',' << fmt(r.mtcd, 6)
      << ',' << fmt(r.temporalError, 6) << ',' << fmt(r.mtcdDisplay, 6) << ',' << fmt(r.rmse, 6) << ','
      << fmt(r.ssim, 6) << ',' << fmt(r.rmseDisplay, 6) << ',' << fmt(r.errPxDisplayPct, 6) << ','
      << fmt(r.stereoError, 6) << ',' << fmt(r.stereoDiff, 6) << ',' << fmt(r.stereoDiffGt, 6) << ','
      << fmt(r.stereoGap, 6) << ',' << fmt(r.ghostWorstRatio, 6) << ',' << r.ghostWorstFrame << ','
      << r.recoveryFrames << ',' << r.recovered << ',' << r.motionChanges << ',' << fmt(r.headSpeedP95, 6)
      << ',' << r.lowSpeed << ',' << r.staticScene << ',' << fmt(r.gpuMs, 6) << ',' << fmt(r.gpuTemporalMs, 6)
      << ',' << fmt(r.gpuStereoMs, 6) << ',' << fmt(r.gpuOtherMs, 6) << ',' << fmt(r.renderMs, 6) << ','
      << fmt(r.costMs, 6) << ',' << fmt(r.cpuUs, 6) << ',' << fmt(r.temporalErrorTruth8, 6) << '\n';
  }
}

void writeResultsJson(const std::string& path, const Options& o, const std::vector<ResultRow>& rows,
                      const std::vector<TargetCheck>& targets, const std::string& device, double seconds) {
  std::ofstream f(path);
  f << "{\n  \"config\": {\"width\": " << o.width << ", \"height\": " << o.height
    << ", \"frames\": " << o.frames << ", \"seed\": " << o.seed << ", \"app_hz\": " << o.appHz
    << ", \"display_hz\": " << o.displayHz << ", \"gt_samples_per_pixel\": " << o.gtGrid * o.gtGrid
    << ", \"error_threshold\": " << o.errorThreshold << ", \"srgb\": " << boolStr(!o.unorm)
    << ", \"mipmaps\": " << boolStr(o.mipmaps) << ", \"corpus\": " << boolStr(o.corpus)
    << ", \"ppd\": " << o.ppd << ", \"cant_deg\": " << o.cantDeg
    << ", \"locomotion\": " << jsonStr(toString(o.locomotion)) << ", \"drop_frames\": " << o.dropFrames
    << ", \"missed_periods\": " << missedPeriods(o.frames, o.dropFrames, o.seed)
    << ", \"device\": " << jsonStr(device)
    << ", \"color_space\": \"display-encoded (sRGB) 8-bit values scaled to [0,1]; MTCD, temporal and stereo "
       "error in 8-bit code values\""
    << ", \"wall_seconds\": " << fmt(seconds, 4) << "},\n  \"results\": [\n";
  for (size_t i = 0; i < rows.size(); ++i) {
    const ResultRow& r = rows[i];
    f << "    {\"scenario\": " << jsonStr(r.scenario) << ", \"scene\": " << jsonStr(r.scene)
      << ", \"motion\": " << jsonStr(r.motion) << ", \"picture\": " << jsonStr(r.picture)
      << ", \"motion_class\": " << jsonStr(r.motionClass)
      << ", \"picture_class\": " << jsonStr(r.pictureClass) << ", \"method\": " << jsonStr(r.method)
      << ", \"filter_method\": " << jsonStr(r.filterMethod) << ", \"sweep\": " << boolStr(r.sweep)
      << ", \"stereo\": " << boolStr(r.stereo) << ", \"jitter\": " << boolStr(r.jitter)
      << ", \"depth_given\": " << boolStr(r.depthGiven) << ", \"samples\": " << r.source
      << ", \"mtcd\": " << fmt(r.mtcd, 6) << ", \"temporal_error\": " << fmt(r.temporalError, 6)
      << ", \"temporal_error_truth8\": " << fmt(r.temporalErrorTruth8, 6)
      << ", \"mtcd_display\": " << fmt(r.mtcdDisplay, 6) << ", \"rmse\": " << fmt(r.rmse, 6)
      << ", \"ssim\": " << fmt(r.ssim, 6) << ", \"rmse_display\": " << fmt(r.rmseDisplay, 6)
      << ", \"error_pixels_display_pct\": " << fmt(r.errPxDisplayPct, 6)
      << ", \"stereo_error\": " << fmt(r.stereoError, 6) << ", \"stereo_gap\": " << fmt(r.stereoGap, 6)
      << ", \"ghost_worst_ratio\": " << fmt(r.ghostWorstRatio, 6)
      << ", \"ghost_worst_frame\": " << r.ghostWorstFrame << ", \"recovery_frames\": " << r.recoveryFrames
      << ", \"recovered\": " << boolStr(r.recovered) << ", \"motion_changes\": " << r.motionChanges
      << ", \"head_speed_p95\": " << fmt(r.headSpeedP95, 6) << ", \"low_speed\": " << boolStr(r.lowSpeed)
      << ", \"gpu_ms\": " << fmt(r.gpuMs, 6) << ", \"render_ms\": " << fmt(r.renderMs, 6)
      << ", \"cost_ms\": " << fmt(r.costMs, 6) << ", \"cpu_us\": " << fmt(r.cpuUs, 6) << "}"
      << (i + 1 < rows.size() ? "," : "") << "\n";
  }
  f << "  ],\n  \"targets\": [\n";
  for (size_t i = 0; i < targets.size(); ++i) {
    f << "    {\"target\": " << jsonStr(targets[i].name)
      << ", \"evaluated\": " << boolStr(targets[i].evaluated) << ", \"met\": " << boolStr(targets[i].met)
      << ", \"detail\": " << jsonStr(targets[i].detail) << "}" << (i + 1 < targets.size() ? "," : "") << "\n";
  }
  f << "  ]\n}\n";
}

void printResults(const std::vector<ResultRow>& rows, const std::vector<TargetCheck>& targets, bool perCase) {
  std::string current;
  for (const ResultRow& r : rows) {
    if (!perCase) break;
    if (r.scenario != current) {
      current = r.scenario;
      std::cout << "\n== " << current << "  (head speed p95 " << fmt(r.headSpeedP95, 3) << " deg/s"
                << (r.lowSpeed ? ", low-speed case" : "") << ", " << r.motionChanges << " motion changes)\n"
                << std::left << std::setw(22) << "method" << std::right << std::setw(8) << "MTCD"
                << std::setw(8) << "TempErr" << std::setw(8) << "RMSE" << std::setw(7) << "SSIM"
                << std::setw(9) << "RMSEdisp" << std::setw(8) << "err%" << std::setw(8) << "StErr"
                << std::setw(8) << "worst/n" << std::setw(6) << "recov" << std::setw(8) << "GPUms"
                << std::setw(8) << "costms"
                << "\n";
    }
    std::cout << std::left << std::setw(22) << r.method << std::right << std::fixed << std::setprecision(3)
              << std::setw(8) << r.mtcd << std::setw(8) << r.temporalError << std::setprecision(4)
              << std::setw(8) << r.rmse << std::setprecision(3) << std::setw(7) << r.ssim
              << std::setprecision(4) << std::setw(9) << r.rmseDisplay << std::setprecision(2) << std::setw(8)
              << r.errPxDisplayPct << std::setprecision(3) << std::setw(8) << r.stereoError << std::setw(8)
              << r.ghostWorstRatio << std::setw(5) << r.recoveryFrames << (r.recovered ? ' ' : '+')
              << std::setw(8) << r.gpuMs << std::setw(8) << r.costMs << "\n";
    std::cout.unsetf(std::ios::fixed);
  }
  std::cout << "\nTargets (issue 14; default = " << core::methodName(core::Params{}) << "):\n";
  for (const TargetCheck& t : targets) {
    std::cout << "  ["
              << (!t.evaluated ? "N/A"
                  : t.met      ? "MET"
                               : "MISSED")
              << "] " << t.name << ": " << t.detail << "\n";
  }
}

}  // namespace steadyxr::eval
