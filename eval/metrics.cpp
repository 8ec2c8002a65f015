#include "metrics.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <array>
#include <cmath>

namespace steadyxr::eval {

double temporalColorDifference(const Image& previous, const Image& current) {
  const size_t n = static_cast<size_t>(current.width) * current.height;
  double sum = 0.0;
  for (size_t i = 0; i < n; ++i) {
    double d2 = 0.0;
    for (int c = 0; c < 3; ++c) {
      const double d = static_cast<double>(previous.rgb[i * 3 + c]) - current.rgb[i * 3 + c];
      d2 += d * d;
    }
    sum += std::sqrt(d2);
  }
  return n ? sum / static_cast<double>(n) : 0.0;
}

double meanSquaredError(const Image& a, const Image& b) {
  double sum = 0.0;
  for (size_t i = 0; i < a.rgb.size(); ++i) {
    const double d = static_cast<double>(a.rgb[i]) - b.rgb[i];
    sum += d * d;
  }
  return a.rgb.empty() ? 0.0 : sum / static_cast<double>(a.rgb.size());
}

double rmse(const Image& a, const Image& b) {
  return std::sqrt(meanSquaredError(a, b));
}

namespace {

std::vector<double> luma(const Image& img) {
  std::vector<double> y(static_cast<size_t>(img.width) * img.height);
  for (size_t i = 0; i < y.size(); ++i) {
    y[i] = 0.299 * img.rgb[i * 3] + 0.587 * img.rgb[i * 3 + 1] + 0.114 * img.rgb[i * 3 + 2];
  }
  return y;
}

// Separable Gaussian blur, "valid" region only: output is (w-10) x (h-10).
std::vector<double> blurValid(const std::vector<double>& in, int w, int h, const std::array<double, 11>& k) {
  const int ow = w - 10, oh = h - 10;
  std::vector<double> tmp(static_cast<size_t>(ow) * h), out(static_cast<size_t>(ow) * oh);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < ow; ++x) {
      double s = 0.0;
      for (int i = 0; i < 11; ++i) s += k[i] * in[static_cast<size_t>(y) * w + x + i];
      tmp[static_cast<size_t>(y) * ow + x] = s;
    }
  }
  for (int y = 0; y < oh; ++y) {
    for (int x = 0; x < ow; ++x) {
      double s = 0.0;
      for (int i = 0; i < 11; ++i) s += k[i] * tmp[static_cast<size_t>(y + i) * ow + x];
      out[static_cast<size_t>(y) * ow + x] = s;
    }
  }
  return out;
}

}  // namespace

double ssim(const Image& a, const Image& b) {
  const int w = a.width, h = a.height;
  if (w < 11 || h < 11) return 1.0 - meanSquaredError(a, b);  // too small for the window
  std::array<double, 11> k{};
  double ksum = 0.0;
  for (int i = 0; i < 11; ++i) {
    k[i] = std::exp(-0.5 * (i - 5) * (i - 5) / (1.5 * 1.5));
    ksum += k[i];
  }
  for (double& v : k) v /= ksum;
  const std::vector<double> x = luma(a), y = luma(b);
  std::vector<double> xx(x.size()), yy(x.size()), xy(x.size());
  for (size_t i = 0; i < x.size(); ++i) {
    xx[i] = x[i] * x[i];
    yy[i] = y[i] * y[i];
    xy[i] = x[i] * y[i];
  }
  const auto mx = blurValid(x, w, h, k), my = blurValid(y, w, h, k);
  const auto sxx = blurValid(xx, w, h, k), syy = blurValid(yy, w, h, k), sxy = blurValid(xy, w, h, k);
  constexpr double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03;
  double sum = 0.0;
  for (size_t i = 0; i < mx.size(); ++i) {
    const double vx = sxx[i] - mx[i] * mx[i], vy = syy[i] - my[i] * my[i], cxy = sxy[i] - mx[i] * my[i];
    sum +=
        ((2 * mx[i] * my[i] + c1) * (2 * cxy + c2)) / ((mx[i] * mx[i] + my[i] * my[i] + c1) * (vx + vy + c2));
  }
  return sum / static_cast<double>(mx.size());
}

int64_t errorPixels(const Image& a, const Image& b, float threshold) {
  int64_t count = 0;
  const size_t n = static_cast<size_t>(a.width) * a.height;
  for (size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) {
      if (std::fabs(a.rgb[i * 3 + c] - b.rgb[i * 3 + c]) > threshold) {
        ++count;
        break;
      }
    }
  }
  return count;
}

namespace {

// Calls visit(x, y, q) for every left-eye pixel whose surface the right eye also sees: the pixel
// is carried into the right eye through the left depth, and rejected when the right eye's depth
// there disagrees (occlusion) or it lands outside; q is its right-eye pixel position.
template <typename Visit>
void forEachStereoPair(const DepthMap& leftDepth, const EyeCamera& leftCam, const DepthMap& rightDepth,
                       const EyeCamera& rightCam, float relativeDepthTolerance, Visit&& visit) {
  const glm::vec3 rightEye = rightCam.pose.position;
  for (int y = 0; y < leftDepth.height; ++y) {
    for (int x = 0; x < leftDepth.width; ++x) {
      const float d = leftDepth.at(x, y);
      if (d >= 1.0f) continue;  // background at the far plane: no disparity information
      const glm::vec3 p = unproject(leftCam, x + 0.5f, y + 0.5f, d);
      glm::vec2 q;
      float qd = 0.0f;
      if (!project(rightCam, p, &q, &qd)) continue;
      const int rx = static_cast<int>(q.x), ry = static_cast<int>(q.y);
      if (q.x < 0.0f || q.y < 0.0f || rx >= rightDepth.width || ry >= rightDepth.height) continue;
      // Occlusion: the right eye must see the same surface there.
      const glm::vec3 seen = unproject(rightCam, rx + 0.5f, ry + 0.5f, rightDepth.at(rx, ry));
      const float dp = glm::length(p - rightEye), ds = glm::length(seen - rightEye);
      if (std::fabs(dp - ds) > relativeDepthTolerance * dp) continue;
      visit(x, y, q);
    }
  }
}

}  // namespace

StereoDifference stereoDifference(const Image& left, const DepthMap& leftDepth, const EyeCamera& leftCam,
                                  const Image& right, const DepthMap& rightDepth, const EyeCamera& rightCam,
                                  float relativeDepthTolerance) {
  double sum = 0.0;
  int64_t valid = 0;
  forEachStereoPair(leftDepth, leftCam, rightDepth, rightCam, relativeDepthTolerance,
                    [&](int x, int y, glm::vec2 q) {
                      float c[3];
                      if (!sampleBilinear(right, q.x, q.y, c)) return;
                      const float* l = left.at(x, y);
                      for (int ch = 0; ch < 3; ++ch)
                        sum += static_cast<double>(l[ch] - c[ch]) * (l[ch] - c[ch]);
                      ++valid;
                    });
  StereoDifference out;
  if (valid > 0) out.meanSquared = sum / (3.0 * static_cast<double>(valid));
  out.validFraction = static_cast<double>(valid) / (static_cast<double>(left.width) * left.height);
  return out;
}

double temporalErrorVsTruth(const Image& previousOut, const Image& out, const Image& previousTruth,
                            const Image& truth) {
  const size_t n = static_cast<size_t>(out.width) * out.height;
  double sum = 0.0;
  for (size_t i = 0; i < n; ++i) {
    double d2 = 0.0;
    for (size_t c = i * 3; c < i * 3 + 3; ++c) {
      const double d = (static_cast<double>(out.rgb[c]) - previousOut.rgb[c]) -
                       (static_cast<double>(truth.rgb[c]) - previousTruth.rgb[c]);
      d2 += d * d;
    }
    sum += std::sqrt(d2);
  }
  return n ? sum / static_cast<double>(n) : 0.0;
}

Image roundTo8Bit(const Image& img) {
  Image out = img;
  for (float& v : out.rgb) v = std::round(std::clamp(v, 0.0f, 1.0f) * 255.0f) / 255.0f;
  return out;
}

double stereoErrorPerPixel(const Image& leftOut, const Image& rightOut, const Image& leftTruth,
                           const Image& rightTruth, const DepthMap& leftDepth, const EyeCamera& leftCam,
                           const DepthMap& rightDepth, const EyeCamera& rightCam,
                           float relativeDepthTolerance) {
  double sum = 0.0;
  int64_t valid = 0;
  forEachStereoPair(
      leftDepth, leftCam, rightDepth, rightCam, relativeDepthTolerance, [&](int x, int y, glm::vec2 q) {
        float ro[3], rt[3];
        if (!sampleBilinear(rightOut, q.x, q.y, ro) || !sampleBilinear(rightTruth, q.x, q.y, rt)) {
          return;
        }
        const float *lo = leftOut.at(x, y), *lt = leftTruth.at(x, y);
        double d2 = 0.0;
        for (int ch = 0; ch < 3; ++ch) {
          const double d = (static_cast<double>(lo[ch]) - ro[ch]) - (static_cast<double>(lt[ch]) - rt[ch]);
          d2 += d * d;
        }
        sum += std::sqrt(d2);
        ++valid;
      });
  return valid > 0 ? sum / static_cast<double>(valid) : 0.0;
}

std::vector<int> detectMotionChanges(const std::vector<double>& headSpeedDegPerSec,
                                     double thresholdDegPerSec) {
  std::vector<int> changes;
  for (size_t k = 1; k < headSpeedDegPerSec.size(); ++k) {
    if (std::fabs(headSpeedDegPerSec[k] - headSpeedDegPerSec[k - 1]) >= thresholdDegPerSec) {
      changes.push_back(static_cast<int>(k));
    }
  }
  return changes;
}

Ghosting ghostingPerFrame(const std::vector<double>& methodRmse, const std::vector<double>& noneRmse,
                          const std::vector<int>& changeFrames) {
  Ghosting g;
  const size_t n = std::min(methodRmse.size(), noneRmse.size());
  // none's error counts as at least the 8-bit floor: below it both are as exact as the display
  // format can be, and a ratio of two such errors says nothing (e.g. 5.9e-5 against 5.3e-5 once the
  // picture has left the view, eval/stress.py).
  auto noneAt = [&](size_t k) { return std::max(noneRmse[k], kEightBitRmseFloor); };
  for (size_t k = 0; k < n; ++k) {
    const double ratio = methodRmse[k] / noneAt(k);
    if (g.worstFrame < 0 || ratio > g.worstRatio) {
      g.worstRatio = ratio;
      g.worstFrame = static_cast<int>(k);
    }
  }
  for (int change : changeFrames) {
    if (change < 0 || static_cast<size_t>(change) >= n) continue;
    size_t k = static_cast<size_t>(change);
    while (k < n && methodRmse[k] > noneAt(k)) ++k;
    if (k == n) g.recovered = false;
    g.recoveryFrames = std::max(g.recoveryFrames, static_cast<int>(k) - change);
  }
  return g;
}

double percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const double rank = std::ceil(std::clamp(p, 0.0, 1.0) * static_cast<double>(values.size()));
  const size_t index = rank < 1.0 ? 0 : static_cast<size_t>(rank) - 1;
  return values[std::min(index, values.size() - 1)];
}

}  // namespace steadyxr::eval
