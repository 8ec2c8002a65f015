// Compares the layer's dumped eye images (PNG) for the end-to-end test.
//   png_compare equal A.png B.png
//       exit 0 when the RGBA pixels are identical; prints the largest channel difference.
//   png_compare changes TOLERANCE DILATE IN.png OUT.png PREV_IN.png...
//       prints "differ=N outside=N changed=N total=N": pixels where OUT differs from IN (by more
//       than TOLERANCE in a channel), those of them outside the region where IN differs from any
//       earlier input (grown by DILATE pixels), that region's size, and the image size.
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_STATIC
#include <stb_image.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

namespace {

struct Image {
  int w = 0;
  int h = 0;
  std::vector<unsigned char> rgba;
  int diff(const Image& o, size_t p, int channels = 3) const {
    int m = 0;
    for (int c = 0; c < channels; ++c)
      m = std::max(m, std::abs(int(rgba[p * 4 + c]) - int(o.rgba[p * 4 + c])));
    return m;
  }
};

bool load(const char* path, Image* out) {
  int n = 0;
  std::unique_ptr<unsigned char, void (*)(void*)> data(stbi_load(path, &out->w, &out->h, &n, 4),
                                                       stbi_image_free);
  if (!data) {
    std::fprintf(stderr, "png_compare: cannot read %s\n", path);
    return false;
  }
  out->rgba.assign(data.get(), data.get() + size_t(out->w) * out->h * 4);
  return true;
}

int usage() {
  std::fprintf(stderr, "usage: png_compare equal A B | changes TOLERANCE DILATE IN OUT PREV...\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) return usage();
  const std::string mode = argv[1];
  if (mode == "equal" && argc == 4) {
    Image a, b;
    if (!load(argv[2], &a) || !load(argv[3], &b)) return 2;
    if (a.w != b.w || a.h != b.h) {
      std::printf("size differs\n");
      return 1;
    }
    int maxDiff = 0;
    size_t count = 0;
    for (size_t p = 0; p < size_t(a.w) * a.h; ++p) {
      const int d = a.diff(b, p, 4);  // RGBA: `none` passes alpha through too
      maxDiff = std::max(maxDiff, d);
      count += d > 0;
    }
    std::printf("max_diff=%d differ=%zu total=%zu\n", maxDiff, count, size_t(a.w) * a.h);
    return maxDiff == 0 ? 0 : 1;
  }
  if (mode == "changes" && argc >= 7) {
    const int tol = std::atoi(argv[2]);
    const int grow = std::atoi(argv[3]);
    Image in, out;
    if (!load(argv[4], &in) || !load(argv[5], &out)) return 2;
    if (out.w != in.w || out.h != in.h) return 2;
    const int w = in.w, h = in.h;
    // Changed region: pixels where this input differs from any earlier input (history may
    // still carry what was there a few frames ago).
    std::vector<unsigned char> changed(size_t(w) * h, 0), near(size_t(w) * h, 0);
    for (int a = 6; a < argc; ++a) {
      Image prev;
      if (!load(argv[a], &prev) || prev.w != w || prev.h != h) return 2;
      for (size_t p = 0; p < changed.size(); ++p) changed[p] |= in.diff(prev, p) > tol;
    }
    size_t changedCount = 0;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        if (!changed[size_t(y) * w + x]) continue;
        ++changedCount;
        for (int dy = -grow; dy <= grow; ++dy) {
          for (int dx = -grow; dx <= grow; ++dx) {
            const int xx = x + dx, yy = y + dy;
            if (xx >= 0 && yy >= 0 && xx < w && yy < h) near[size_t(yy) * w + xx] = 1;
          }
        }
      }
    }
    size_t differ = 0, outside = 0;
    for (size_t p = 0; p < changed.size(); ++p) {
      if (out.diff(in, p) > tol) {
        ++differ;
        outside += !near[p];
      }
    }
    std::printf("differ=%zu outside=%zu changed=%zu total=%zu\n", differ, outside, changedCount,
                changed.size());
    return 0;
  }
  return usage();
}
