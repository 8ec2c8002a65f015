// steadyxr-bench: GPU ms per stereo frame (Vulkan timestamp queries) of each pass and of the
// default pipeline, beside a plain copy pass measured in the same run, plus the host (CPU) time
// of the per-frame work in submit(). Figures, not a test. Beside each: the bytes per pixel of the
// traffic model (traffic_model.h) and its ratio to the copy's.
#include <vulkan/vulkan.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <glm/gtc/quaternion.hpp>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench_input.h"
#include "steadyxr/core/filter.h"
#include "steadyxr/core/params.h"
#include "steadyxr/core/vulkan_context.h"
#include "traffic_model.h"

using namespace steadyxr::core;

namespace {

// @noisetold: a render noise of 0.02 standard deviation per linear RGB channel (the stress draws' noise
// amplitudes, 0.01-0.08, are uniform: a standard deviation of 0.58x that).
constexpr float kToldNoiseVariance = 0.02f * 0.02f;

struct Options {
  std::vector<VkExtent2D> sizes{{1024, 1024}, {1440, 1600}, {2064, 2208}};
  std::vector<std::string> methods{"none", "fxaa", "taa", "hmtaa", "vtaa", "hybrid", "stereo", "default"};
  int iterations = 20;
  int warmup = 3;
  // Warm-up also lasts this long at each size; -1: 2000 ms on a GPU, none on a CPU device. A GPU's clock
  // rose from 345 MHz to 1980 within 0.2-1 s of steady work and fell back within 0.4 s of idling (an
  // H200, round 29, sampled every 200 ms): the picture's rendering and the pipelines' creation idle it.
  int warmupMs = -1;
  std::string csv;
  bool pipelines = false;                     // print each method's pipelines (for steadyxr-shader-stats)
  VkFormat format = VK_FORMAT_R8G8B8A8_SRGB;  // of the app's input and output images
  InvocationBlock block = InvocationBlock::Auto;
  bool flatInput = false;  // --input flat: one clear colour instead of the rendered picture
  bool depth = false;      // --depth: every eye with a depth image (one plane)
};

// The head's tremor over the frames: a yaw that steps through kTremorPoses orientations, so that every
// frame reprojects (bench_input.h renders the picture for each).
constexpr int kTremorPoses = 7;
glm::quat tremorOrientation(int frame) {
  return glm::angleAxis(0.001f * float(frame % kTremorPoses), glm::vec3(0, 1, 0));
}
constexpr Fov kBenchFov{-0.8f, 0.75f, 0.78f, -0.82f};

void usage() {
  std::cout
      << "usage: steadyxr-bench [--sizes WxH[,WxH...]] [--methods m1,m2,...] [--iterations N]\n"
         "                      [--warmup N] [--warmup-ms MS] [--format srgb8|unorm8|rgba16f] [--csv FILE]\n"
         "                      [--block auto|1x1|4x4] [--input picture|flat] [--depth] [--pipelines]\n"
         "Per-eye sizes; 'none' is the plain copy pass every ratio is relative to (each iteration\n"
         "runs every method once, the copy first; a ratio is the median over iterations of the\n"
         "method's time over the copy's in the same iteration). Warm-up: --warmup iterations and\n"
         "at least --warmup-ms (default 2000 on a GPU, 0 on a CPU device). A method may end in\n"
         "@history=16 or @history=8 (the history's bits per channel, Params::historyFormat).\n"
         "'model' is the traffic model's bytes per pixel of one eye (traffic_model.h) and its\n"
         "ratio to the copy's; 'ops' its fetches+samples+stores per pixel; 'probe' the median GPU\n"
         "time of steady's probe dispatches (part of the method's time; the timestamps' own cost\n"
         "for the others). <method>@catmull: the method with the Catmull-Rom history.\n"
         "@blend: the far plane at the nearest depth, so\n"
         "that steady+stereo blends without depth (else it skips the pass: the disparity's\n"
         "spread exceeds a pixel); @tapcurv=0: stereo without the tap's curvature correction;\n"
         "@curvbox, @curvbox=0: steady's clip box bounded by second differences or not "
         "(steadyClipCurvature); @curvcentre, @curvcentre=0, @quantsrgb, @quantsrgb=0: the\n"
         "one-sided curvature box and the sRGB quantisation floor, or not\n"
         "(steadyClipCurvatureCentred, steadyClipQuantSrgb); @curvgate: the one-sided box only\n"
         "where the history lags on one side (steadyClipCurvatureCentredGated, an option);\n"
         "@noisy, @noisy=0: the render's noise estimated and the box widened by it, or not\n"
         "(steadyNoiseEstimate; the default since round 15); @gain=0: without the frame's gain\n"
         "probe and its compensation (steadyGainCompensation; the default since round 16);\n"
         "@hold=0: the 8-bit output rounded, not held (steadyOutputHold; held since round 20).\n"
         "@noisetold: the render's noise told (0.02^2 a channel), not estimated: the passes act\n"
         "on it in every pixel; @blurnoise, @blurnoise=0: round 26's blur\n"
         "guard traded against that noise, or not (steadyBlurNoiseTrade); @cut=0: no fresh start\n"
         "where the pose does not explain a frame (steadyUnexplainedFrameResets; on since round 31);\n"
         "@hudswitch=0: without the head-locked switch (steadyHeadLockedSwitch; on since round 42).\n"
         "--input: the eye images, a zone plate rendered for each frame's pose (the default since\n"
         "round 28: detail, aliasing and chroma, as an app's frames) or one flat colour (before).\n"
         "--depth: every eye with a D32 depth image, one plane at half the range (the passes' depth\n"
         "paths; round 48's item 15 is compiled in only there). @resolved=0: without it.\n"
         "--pipelines: after each method, the pipelines it used as PASS:STORAGE:SPECIALISATION,\n"
         "the arguments of steadyxr-shader-stats (registers and instructions on a GPU's compiler).\n";
}

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

bool parse(int argc, char** argv, Options* o) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string { return i + 1 < argc ? argv[++i] : ""; };
    if (a == "--sizes") {
      o->sizes.clear();
      for (const auto& s : split(next())) {
        unsigned w = 0, h = 0;
        if (std::sscanf(s.c_str(), "%ux%u", &w, &h) != 2 || w == 0 || h == 0) return false;
        o->sizes.push_back({w, h});
      }
    } else if (a == "--methods") {
      o->methods = split(next());
    } else if (a == "--iterations") {
      o->iterations = std::max(1, std::atoi(next().c_str()));
    } else if (a == "--warmup") {
      o->warmup = std::max(0, std::atoi(next().c_str()));
    } else if (a == "--warmup-ms") {
      o->warmupMs = std::max(0, std::atoi(next().c_str()));
    } else if (a == "--format") {
      const std::string f = next();
      if (f == "srgb8")
        o->format = VK_FORMAT_R8G8B8A8_SRGB;
      else if (f == "unorm8")
        o->format = VK_FORMAT_R8G8B8A8_UNORM;
      else if (f == "rgba16f")
        o->format = VK_FORMAT_R16G16B16A16_SFLOAT;
      else
        return false;
    } else if (a == "--block") {
      const std::string b = next();
      if (b == "auto")
        o->block = InvocationBlock::Auto;
      else if (b == "1x1")
        o->block = InvocationBlock::OnePixel;
      else if (b == "4x4")
        o->block = InvocationBlock::FourByFour;
      else
        return false;
    } else if (a == "--csv") {
      o->csv = next();
    } else if (a == "--input") {
      const std::string in = next();
      if (in != "picture" && in != "flat") return false;
      o->flatInput = in == "flat";
    } else if (a == "--depth") {
      o->depth = true;
    } else if (a == "--pipelines") {
      o->pipelines = true;
    } else {
      return false;
    }
  }
  return !o->sizes.empty() && !o->methods.empty();
}

// One image with memory; the bench's own RAII (the core's helpers are internal).
class Image {
 public:
  Image(VulkanContext& ctx, VkFormat f, VkExtent2D e, VkImageUsageFlags usage, bool mutableFormat)
      : ctx_(ctx), format_(f), extent_(e), usage_(usage), mutable_(mutableFormat) {
    VkImageCreateInfo ici{};
    ici.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
    ici.flags = mutableFormat ? VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT | VK_IMAGE_CREATE_EXTENDED_USAGE_BIT : 0;
    ici.imageType = VK_IMAGE_TYPE_2D;
    ici.format = f;
    ici.extent = {e.width, e.height, 1};
    ici.mipLevels = 1;
    ici.arrayLayers = 1;
    ici.samples = VK_SAMPLE_COUNT_1_BIT;
    ici.tiling = VK_IMAGE_TILING_OPTIMAL;
    ici.usage = usage;
    if (vkCreateImage(ctx.device(), &ici, nullptr, &image_) != VK_SUCCESS) throw std::runtime_error("image");
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(ctx.device(), image_, &req);
    VkMemoryAllocateInfo mai{};
    mai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    mai.allocationSize = req.size;
    mai.memoryTypeIndex = ctx.findMemoryType(req.memoryTypeBits, 0, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    if (vkAllocateMemory(ctx.device(), &mai, nullptr, &memory_) != VK_SUCCESS)
      throw std::runtime_error("memory");
    vkBindImageMemory(ctx.device(), image_, memory_, 0);
  }
  ~Image() {
    vkDestroyImage(ctx_.device(), image_, nullptr);
    vkFreeMemory(ctx_.device(), memory_, nullptr);
  }
  Image(const Image&) = delete;
  Image& operator=(const Image&) = delete;
  ImageRef ref(VkImageLayout layout) const {
    ImageRef r;
    r.image = image_;
    r.format = format_;
    r.extent = extent_;
    r.rect = {{0, 0}, extent_};
    r.usage = usage_;
    r.mutableFormat = mutable_;
    r.layout = layout;
    return r;
  }
  VkImage image() const { return image_; }

 private:
  VulkanContext& ctx_;
  VkFormat format_;
  VkExtent2D extent_;
  VkImageUsageFlags usage_;
  bool mutable_;
  VkImage image_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}
// CPU time of the whole process (all threads, lavapipe's workers included): on a shared, loaded
// machine this is far steadier than wall-clock timestamps for a CPU "GPU".
double processCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) * 1e-6;
}
// CPU time of the calling thread alone: the host work of submit() without the time the thread
// waits while llvmpipe's workers hold the cores (wall time, hostUs, includes that).
double threadCpuUs() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) * 1e6 + double(ts.tv_nsec) * 1e-3;
}
double minimum(const std::vector<double>& v) {
  return v.empty() ? 0.0 : *std::min_element(v.begin(), v.end());
}

struct Row {
  VkExtent2D size;
  std::string method;
  double gpuMs, copyMs, hostUs, hostCpuUs;
  double gpuMinMs, copyMinMs;  // minimum over iterations: less sensitive to a shared, loaded CPU
  double cpuMs, copyCpuMs;     // process CPU ms per frame (lavapipe's work), median
  double ratioToCopy;          // median over iterations of the method's GPU time over the copy's in it
  double cpuRatioToCopy;       // the same of the process CPU time
  steadyxr::bench::Traffic model;
  double probeMs;  // of gpuMs: steady's probe of the frame (PassTimings::probeMs), median
};

// The median over iterations of a[i] / b[i]: a method against the copy run in the same iteration.
double pairedRatio(const std::vector<double>& a, const std::vector<double>& b) {
  std::vector<double> ratios;
  for (size_t i = 0; i < std::min(a.size(), b.size()); ++i)
    if (b[i] > 0) ratios.push_back(a[i] / b[i]);
  return median(ratios);
}

// "name" or "name@history=16|8": the method's parameters.
std::optional<Params> methodParams(const std::string& spec) {
  size_t at = spec.find('@');
  auto params = applyMethodName(spec.substr(0, at));
  while (params && at != std::string::npos) {
    const size_t next = spec.find('@', at + 1);
    const std::string suffix =
        spec.substr(at + 1, next == std::string::npos ? std::string::npos : next - at - 1);
    at = next;
    if (suffix == "history=16")
      params->historyFormat = HistoryFormat::Rgba16f;
    else if (suffix == "history=8")
      params->historyFormat = HistoryFormat::Rgba8Dithered;
    else if (suffix == "catmull")  // the steady candidate's cost (docs/method-history.md, "The worst frames")
      params->historyFilter = HistoryFilter::CatmullRom;
    else if (suffix == "blend")  // the bench has no depth: a scene assumed at the nearest distance
      params->stereoFarDistanceM =
          params->steadyNearestDepthM;  // has no disparity spread, so steady+stereo blends
    else if (suffix == "tapcurv=0")
      params->stereoTapCurvature = false;
    else if (suffix == "curvbox")  // steady's clip box bounded by second differences (Params)
      params->steadyClipCurvature = true;
    else if (suffix == "curvbox=0")  // the default without it (round 6's cost comparison)
      params->steadyClipCurvature = false;
    else if (suffix == "curvcentre")  // round 7: the curvature box one-sided (Params; the default)
      params->steadyClipCurvatureCentred = true;
    else if (suffix == "curvcentre=0")  // the default without it (round 6's box)
      params->steadyClipCurvatureCentred = false;
    else if (suffix == "curvgate")  // round 10's option: the one-sided box where the history lags one side
      params->steadyClipCurvatureCentredGated = true;
    else if (suffix == "curvgate=0")  // the default
      params->steadyClipCurvatureCentredGated = false;
    else if (suffix == "quantsrgb")  // the clip's floor half an sRGB step (Params; the default)
      params->steadyClipQuantSrgb = true;
    else if (suffix == "quantsrgb=0")  // the default with the linear floor (round 7's cost comparison)
      params->steadyClipQuantSrgb = false;
    else if (suffix == "noisy")  // the noise estimate and the box widened by it (the default since round 15)
      params->steadyNoiseEstimate = true;
    else if (suffix == "noisy=0")  // the default without it (the default before round 15)
      params->steadyNoiseEstimate = false;
    else if (suffix == "gain=0")  // the default without the gain probe (the default before round 16)
      params->steadyGainCompensation = false;
    else if (suffix == "hold=0")  // the default with plain rounding (the default before round 20)
      params->steadyOutputHold = 0.0f;
    else if (suffix == "noisetold") {  // the noise told, not estimated: the pass acts on it everywhere
      params->steadyNoiseEstimate = false;
      params->steadyNoiseVariance = kToldNoiseVariance;
    } else if (suffix == "blurnoise")  // round 26: the blur guard traded against the noise (with noisetold)
      params->steadyBlurNoiseTrade = true;
    else if (suffix == "blurnoise=0")
      params->steadyBlurNoiseTrade = false;
    else if (suffix == "cut=0")  // round 31: no fresh start where the pose does not explain a frame
      params->steadyUnexplainedFrameResets = false;
    else if (suffix == "hudswitch=0")  // round 42: without the head-locked switch (the default before)
      params->steadyHeadLockedSwitch = false;
    else if (suffix == "resolved=0")  // round 48: without item 15 (compiled in only with depth: --depth)
      params->steadyResolvedEdges = false;
    else
      return std::nullopt;
  }
  return params;
}

// PASS:STORAGE:k0,k1,... per pipeline: steadyxr-shader-stats takes these as they are.
void printPipelines(const std::string& method, const std::vector<PipelineDescription>& pipelines) {
  for (const PipelineDescription& p : pipelines) {
    std::string spec;
    for (const int32_t v :
         p.specialisation) {  // appended: GCC 12 at -O3 warns (-Wrestrict) on "," + std::string&&
      if (!spec.empty()) spec += ',';
      spec += std::to_string(v);
    }
    std::printf("pipeline of %s: %s:%s:%s\n", method.c_str(), p.pass.c_str(), p.storage.c_str(),
                spec.c_str());
  }
}

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  if (!parse(argc, argv, &opt)) {
    usage();
    return 2;
  }
  std::string err;
  auto ctx = VulkanContext::createOwned(OwnedContextOptions{}, &err);
  if (!ctx) {
    std::cerr << "steadyxr-bench: " << err << "\n";
    return 1;
  }
  std::cout << "device: " << ctx->properties().deviceName << "\n";
  std::vector<Row> rows;
  for (const VkExtent2D size : opt.sizes) {
    const VkImageUsageFlags outUsage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    std::array<std::unique_ptr<Image>, 2> out;
    for (auto& o : out)
      o = std::make_unique<Image>(*ctx, opt.format, size, outUsage, opt.format == VK_FORMAT_R8G8B8A8_SRGB);
    // One input per tremor pose, both eyes' (the picture lies at infinity: the eyes' offset moves nothing).
    std::vector<std::unique_ptr<Image>> in(opt.flatInput ? 1 : kTremorPoses);
    for (size_t k = 0; k < in.size(); ++k) {
      in[k] = std::make_unique<Image>(*ctx, opt.format, size,
                                      VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT, false);
      // --input flat: the bench's input before round 28, one colour everywhere.
      if (opt.flatInput) {
        if (!steadyxr::bench::clearImage(*ctx, in[k]->image(), glm::vec4(0.2f, 0.4f, 0.6f, 1.0f), &err)) {
          std::cerr << "steadyxr-bench: the flat input: " << err << "\n";
          return 1;
        }
      } else if (!steadyxr::bench::uploadImage(
                     *ctx, in[k]->image(), opt.format, size,
                     steadyxr::bench::renderZonePlate(size, kBenchFov, tremorOrientation(int(k))), &err)) {
        std::cerr << "steadyxr-bench: the input picture: " << err << "\n";
        return 1;
      }
    }
    std::unique_ptr<Image> depth;
    if (opt.depth) {
      depth = std::make_unique<Image>(*ctx, VK_FORMAT_D32_SFLOAT, size,
                                      VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT, false);
      if (!steadyxr::bench::clearDepthImage(*ctx, depth->image(), 0.5f, &err)) {
        std::cerr << "steadyxr-bench: the depth image: " << err << "\n";
        return 1;
      }
    }
    // Every iteration runs each method once, in turn, the copy first, and a method's ratio is the median
    // over iterations of its time over the copy's in the same iteration. A GPU's clock drops to a fraction
    // between short submissions and rises again, seconds at a time (an H200: 345 MHz against 1980, round
    // 29), and lavapipe's cores are shared with the machine's other work: paired frames see the same
    // clock and load, where whole runs of one method after another did not.
    std::vector<std::string> methods;
    for (const std::string& m : opt.methods)
      if (m != "none") methods.push_back(m);
    methods.insert(methods.begin(), "none");
    struct Method {
      std::unique_ptr<Filter> filter;
      steadyxr::bench::Traffic model;
      std::vector<double> gpu, probe, host, hostCpu, cpu;
    };
    std::vector<Method> runs;
    for (const std::string& m : methods) {
      auto params = methodParams(m);
      if (!params) {
        std::cerr << "unknown method " << m << "\n";
        return 2;
      }
      params->invocationBlock = opt.block;
      const bool blocked = opt.block == InvocationBlock::FourByFour ||
                           (opt.block == InvocationBlock::Auto && ctx->isCpuDevice());
      Method run;
      run.model = steadyxr::bench::modelTraffic(*params, opt.format, blocked);
      run.filter = Filter::create(*ctx, *params, &err);
      if (!run.filter) {
        std::cerr << "steadyxr-bench: " << err << "\n";
        return 1;
      }
      runs.push_back(std::move(run));
    }
    VkImageLayout outLayout = VK_IMAGE_LAYOUT_UNDEFINED;  // the output images are every method's
    const int warmupMs = opt.warmupMs >= 0 ? opt.warmupMs : ctx->isCpuDevice() ? 0 : 2000;
    const auto warmupStart = std::chrono::steady_clock::now();
    for (int i = 0, measured = 0; measured < opt.iterations; ++i) {
      const bool warming = i < opt.warmup || std::chrono::steady_clock::now() - warmupStart <
                                                 std::chrono::milliseconds(warmupMs);
      if (!warming) ++measured;
      for (Method& run : runs) {
        StereoFrame f;
        StereoOutput o;
        f.headSpeedDegPerSec = 4.0f;
        for (int e = 0; e < 2; ++e) {
          f.views[e].color = in[size_t(i) % in.size()]->ref(VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
          f.views[e].pose.orientation = tremorOrientation(i);
          f.views[e].pose.position = {e == 0 ? -0.032f : 0.032f, 0.0f, 0.0f};
          f.views[e].fov = kBenchFov;
          if (depth) f.views[e].depth = DepthRef{depth->ref(VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL)};
          o.views[e] = out[e]->ref(outLayout);
          o.views[e].finalLayout = VK_IMAGE_LAYOUT_GENERAL;
        }
        run.filter->waitIdle();  // host time below is the recording/submission only, no GPU wait
        const double c0 = processCpuMs();
        const double h0 = threadCpuUs();
        const auto t0 = std::chrono::steady_clock::now();
        const bool ok = run.filter->submit(f, o, &err);
        const auto t1 = std::chrono::steady_clock::now();
        const double h1 = threadCpuUs();
        if (!ok) {
          std::cerr << "submit failed: " << err << "\n";
          return 1;
        }
        outLayout = VK_IMAGE_LAYOUT_GENERAL;
        run.filter->waitIdle();
        const double c1 = processCpuMs();
        if (warming) continue;
        const auto t = run.filter->lastTimings();
        run.cpu.push_back(c1 - c0);
        run.host.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
        run.hostCpu.push_back(h1 - h0);
        run.gpu.push_back(t ? t->totalMs : 0.0);
        run.probe.push_back(t ? t->probeMs : 0.0);
      }
    }
    const Method& copy = runs.front();
    for (size_t k = 0; k < runs.size(); ++k) {
      Method& me = runs[k];
      for (const auto& image : in) me.filter->forgetImage(image->image());
      for (const auto& image : out) me.filter->forgetImage(image->image());
      if (depth) me.filter->forgetImage(depth->image());
      if (opt.pipelines) printPipelines(methods[k], me.filter->pipelines());
      rows.push_back({size, k == 0 ? "copy (none)" : methods[k], median(me.gpu), median(copy.gpu),
                      median(me.host), median(me.hostCpu), minimum(me.gpu), minimum(copy.gpu), median(me.cpu),
                      median(copy.cpu), pairedRatio(me.gpu, copy.gpu), pairedRatio(me.cpu, copy.cpu),
                      me.model, median(me.probe)});
      const Row& r = rows.back();
      std::printf(
          "%5ux%-5u %-18s gpu %8.3f ms x%5.2f copy | model %4.1f B/px x%4.2f, ops %5.2f | "
          "min %8.3f ms x%5.2f | cpu %8.3f ms x%5.2f | host %7.1f us (thread cpu %5.1f) | probe %6.3f ms\n",
          size.width, size.height, r.method.c_str(), r.gpuMs, r.ratioToCopy, r.model.total(),
          r.model.total() / copy.model.total(), r.model.fetches + r.model.samples + r.model.stores,
          r.gpuMinMs, r.copyMinMs > 0 ? r.gpuMinMs / r.copyMinMs : 0.0, r.cpuMs, r.cpuRatioToCopy, r.hostUs,
          r.hostCpuUs, r.probeMs);
    }
    // What the pairing took out: the copy's own drift over the run (its first and last quarter).
    const auto quarter = std::ptrdiff_t(std::min(copy.gpu.size(), std::max<size_t>(1, copy.gpu.size() / 4)));
    const std::vector<double> firstQuarter(copy.gpu.begin(), copy.gpu.begin() + quarter);
    const std::vector<double> lastQuarter(copy.gpu.end() - quarter, copy.gpu.end());
    std::printf("%5ux%-5u copy's median over the first quarter of iterations %.3f ms, the last %.3f ms\n",
                size.width, size.height, median(firstQuarter), median(lastQuarter));
    std::fflush(stdout);
  }
  std::printf(
      "\n| per-eye size | method | GPU ms/stereo frame (median) | x copy | model B/px (read+write) | "
      "model x copy | GPU ms (min) | x copy (min) | CPU ms (lavapipe) | x copy (CPU) | host us | "
      "host us (thread CPU) |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  const double copyBytes = 2.0 * (opt.format == VK_FORMAT_R16G16B16A16_SFLOAT ? 8.0 : 4.0);
  for (const Row& r : rows)
    std::printf("| %ux%u | %s | %.3f | %.2f | %.0f+%.0f | %.2f | %.3f | %.2f | %.3f | %.2f | %.1f | %.1f |\n",
                r.size.width, r.size.height, r.method.c_str(), r.gpuMs, r.ratioToCopy, r.model.readBytes,
                r.model.writeBytes, r.model.total() / copyBytes, r.gpuMinMs,
                r.copyMinMs > 0 ? r.gpuMinMs / r.copyMinMs : 0.0, r.cpuMs, r.cpuRatioToCopy, r.hostUs,
                r.hostCpuUs);
  if (!opt.csv.empty()) {
    std::ofstream csv(opt.csv);
    csv << "width,height,method,gpu_ms,copy_ms,ratio_to_copy,gpu_min_ms,copy_min_ms,ratio_min,cpu_ms,copy_"
           "cpu_ms,ratio_cpu,host_us,host_cpu_us,model_bytes_per_px\n";
    for (const Row& r : rows)
      csv << r.size.width << "," << r.size.height << "," << r.method << "," << r.gpuMs << "," << r.copyMs
          << "," << r.ratioToCopy << "," << r.gpuMinMs << "," << r.copyMinMs << ","
          << (r.copyMinMs > 0 ? r.gpuMinMs / r.copyMinMs : 0.0) << "," << r.cpuMs << "," << r.copyCpuMs << ","
          << r.cpuRatioToCopy << "," << r.hostUs << "," << r.hostCpuUs << "," << r.model.total() << "\n";
    if (!csv) {
      std::cerr << "could not write " << opt.csv << "\n";
      return 1;
    }
  }
  return 0;
}
