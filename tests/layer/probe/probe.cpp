// steadyxr-probe: a small OpenXR + Vulkan app that submits what hello_xr never does, case by
// case, each in its own session (so every case after the first is also a session restart):
// per-eye, array and side-by-side swapchains, alpha-blended layers (premultiplied and not),
// depth, several projection layers plus a quad, sRGB/UNORM/FP16, a size change, and invalid
// xrEndFrame calls. XR_KHR_vulkan_enable2 (v2) or XR_KHR_vulkan_enable (v1, asking only for
// the Vulkan extensions the device has). Each case checks its result and prints one line:
//   case NAME ok|FAIL detail
// Layer-side checks read the layer's session summary (STEADYXR_LOG_FILE) and its dumped PNGs
// (STEADYXR_DUMP_DIR), when the layer is loaded (--layer). Exit 0 when every case passed.
#include "probe_xr.h"

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-but-set-variable"
#include <stb/stb_image.h>
#pragma GCC diagnostic pop

namespace probe {
namespace {

namespace fs = std::filesystem;

std::string readAll(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The layer's newest "session summary" line, and a counter from it.
std::string lastSummary(const std::string& logFile) {
  const std::string text = readAll(logFile);
  const size_t at = text.rfind("session summary:");
  if (at == std::string::npos) return {};
  return text.substr(at, text.find('\n', at) - at);
}
long counter(const std::string& summary, const std::string& key) {
  const size_t at = summary.find(" " + key + "=");
  return at == std::string::npos ? -1 : std::atol(summary.c_str() + at + key.size() + 2);
}

struct PngPair {
  std::string in, out;
};
bool isInputDump(const std::string& p) {
  return p.size() >= 7 && p.compare(p.size() - 7, 7, "_in.png") == 0;
}

// Dumped pairs not seen before (each session dumps its own files, see dump.h).
std::vector<PngPair> newDumps(const std::string& dir, std::set<std::string>* seen) {
  std::vector<PngPair> pairs;
  std::error_code ec;
  if (dir.empty() || !fs::is_directory(dir, ec)) return pairs;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string p = e.path().string();
    if (!isInputDump(p) || seen->count(p)) continue;
    seen->insert(p);
    pairs.push_back({p, p.substr(0, p.size() - 7) + "_out.png"});
  }
  return pairs;
}

// How many input images the layer has dumped into the folder so far.
size_t dumpCount(const std::string& dir) {
  size_t n = 0;
  std::error_code ec;
  if (dir.empty() || !fs::is_directory(dir, ec)) return 0;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    n += isInputDump(e.path().string());
  }
  return n;
}

// Compares dumped input and output: alpha must match exactly, and with `rgbToo` all channels.
std::string comparePngs(const std::vector<PngPair>& pairs, bool rgbToo, long* alphaPixels) {
  for (const PngPair& pp : pairs) {
    int w = 0, h = 0, n = 0, w2 = 0, h2 = 0, n2 = 0;
    unsigned char* a = stbi_load(pp.in.c_str(), &w, &h, &n, 4);
    unsigned char* b = stbi_load(pp.out.c_str(), &w2, &h2, &n2, 4);
    std::string err;
    if (!a || !b || w != w2 || h != h2) {
      err = "cannot read " + pp.in + " / its _out";
    } else {
      for (long i = 0; i < long(w) * h && err.empty(); ++i) {
        if (a[i * 4 + 3] != 255) ++*alphaPixels;
        for (int k = rgbToo ? 0 : 3; k < 4; ++k)
          if (a[i * 4 + k] != b[i * 4 + k]) {
            err = fs::path(pp.in).filename().string() + ": pixel " + std::to_string(i) + " channel " +
                  std::to_string(k) + " in " + std::to_string(a[i * 4 + k]) + " out " +
                  std::to_string(b[i * 4 + k]);
            break;
          }
      }
    }
    stbi_image_free(a);
    stbi_image_free(b);
    if (!err.empty()) return err;
  }
  return {};
}

struct Options {
  Api api = Api::V2;
  bool layer = false;     // the steadyxr layer is loaded: check its summary and dumps
  bool bitExact = false;  // the layer runs method none: dumped output == input in RGBA
  int frames = 24;
  std::vector<std::string> cases;
};

int run(const Options& o) {
  const char* logEnv = std::getenv("STEADYXR_LOG_FILE");
  const char* dumpEnv = std::getenv("STEADYXR_DUMP_DIR");
  const std::string logFile = logEnv ? logEnv : "";
  const std::string dumpDir = dumpEnv ? dumpEnv : "";
  std::set<std::string> seenDumps;
  Xr xr;
  if (!xr.init(o.api)) {
    std::printf("case init FAIL %s\n", xr.error.c_str());
    return 1;
  }
  std::printf("probe: %s, Vulkan device %s, instance API 1.%u, device extensions enabled: %s\n",
              o.api == Api::V1 ? "XR_KHR_vulkan_enable (v1)" : "XR_KHR_vulkan_enable2 (v2)",
              xr.deviceName.c_str(), VK_API_VERSION_MINOR(xr.instanceApiVersion),
              xr.enabledDeviceExtensions.c_str());
  int failures = 0;
  for (const std::string& name : o.cases) {
    const CaseSpec spec = caseSpec(name);
    // The layer dumps the first frames it filters as it ends them: a new dump means it filters.
    const size_t dumpsBefore = dumpCount(dumpDir);
    std::function<bool()> layerFiltering;
    if (o.layer) layerFiltering = [&] { return dumpCount(dumpDir) > dumpsBefore; };
    CaseResult r = xr.runCase(spec, o.frames, layerFiltering);
    std::string detail = r.detail;
    bool ok = r.ok;
    if (ok && o.layer && spec.kind != CaseKind::Invalid) {
      const std::string summary = lastSummary(logFile);
      const long filtered = counter(summary, "frames_filtered");
      const long passed = counter(summary, "frames_passed_through");
      const long warming = counter(summary, "frames_warming_up");
      const long late = counter(summary, "frames_warming_up_late");
      char buf[160];
      std::snprintf(buf, sizeof buf, " layer: filtered=%ld warming_up=%ld (late %ld) passed=%ld", filtered,
                    warming, late, passed);
      detail += buf;
      if (spec.expectFiltered) {
        // Pipelines compile in the background: the first frames of a session pass through as
        // frames_warming_up (how many depends on the machine's load); every other frame must
        // be filtered, and at least 3 (the frames dumped). None waits once filtering has begun
        // (frames_warming_up_late): no case asks for a new pipeline half-way.
        const long empty = spec.loading ? kLoadingFrames : 0;
        ok = passed == 0 && late == 0 && filtered >= 3 && filtered + warming + empty == o.frames;
        if (spec.loading) {
          // The frame after the loading screen starts without the history (layer/xr/src/
          // history_continuity.h). Up to two more drops are the machine's: a stall of more than
          // 4.5 frame periods (225 ms at the null compositor's 20 Hz) drops it too. A layer that
          // never drops, or drops every frame, fails.
          const long dropped = counter(summary, "history_dropped");
          const bool filteringBefore = warming < loadingStart(o.frames);
          ok = ok && filteringBefore && dropped >= 1 && dropped <= 3;
          detail += " history_dropped=" + std::to_string(dropped) +
                    (filteringBefore ? "" : " (still warming up at the loading screen: more --frames)");
        }
        if (spec.dynamicResolution) {
          // The first filtered frame is 0.8 of the image, the next the whole image: the filter's images
          // are reallocated once, and never again as the size goes on changing. Only a temporal method
          // keeps a history (method none: 0); the default keeps it across each change after that, but
          // where the history was dropped (a stall of the machine, as in the loading case).
          const long changes = counter(summary, "render_size_changes");
          const long kept = counter(summary, "history_kept_resized");
          const long reallocated = counter(summary, "images_reallocated");
          const long dropped = counter(summary, "history_dropped");
          const bool keptRight = o.bitExact ? kept == 0 : kept >= changes - 1 - dropped;
          ok = ok && reallocated == 1 && changes >= 3 && keptRight;
          detail += " render_size_changes=" + std::to_string(changes) +
                    " history_kept_resized=" + std::to_string(kept) +
                    " images_reallocated=" + std::to_string(reallocated);
        }
      } else {
        ok = filtered == 0 && passed > 0 && summary.find(spec.expectReason) != std::string::npos;
        detail += " (expected passed through: " + spec.expectReason + ")";
      }
      long alphaPixels = 0;
      const std::vector<PngPair> dumps = newDumps(dumpDir, &seenDumps);
      if (spec.expectFiltered && spec.dumpable) {
        const std::string err = comparePngs(dumps, o.bitExact, &alphaPixels);
        if (dumps.empty()) {
          ok = false;
          detail += " no dumped images";
        } else if (!err.empty()) {
          ok = false;
          detail += " dump mismatch: " + err;
        } else {
          detail += " dumps=" + std::to_string(dumps.size()) + (o.bitExact ? " rgba==" : " alpha==") +
                    " translucent_px=" + std::to_string(alphaPixels);
          if (spec.translucent && alphaPixels == 0) {
            ok = false;
            detail += " (no translucent pixel was dumped)";
          }
        }
      }
    }
    std::printf("case %s %s%s\n", name.c_str(), ok ? "ok" : "FAIL", detail.c_str());
    std::fflush(stdout);
    failures += ok ? 0 : 1;
  }
  return failures == 0 ? 0 : 1;
}

}  // namespace
}  // namespace probe

int main(int argc, char** argv) {
  probe::Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--v1") {
      o.api = probe::Api::V1;
    } else if (a == "--v2") {
      o.api = probe::Api::V2;
    } else if (a == "--layer") {
      o.layer = true;
    } else if (a == "--bit-exact") {
      o.bitExact = true;
    } else if (a == "--frames" && i + 1 < argc) {
      o.frames = std::atoi(argv[++i]);
    } else {
      o.cases.push_back(a);
    }
  }
  if (o.cases.empty()) {
    std::fprintf(stderr, "usage: steadyxr-probe [--v1|--v2] [--layer] [--bit-exact] [--frames N] CASE...\n");
    return 2;
  }
  return probe::run(o);
}
