#include "resolved_edges.h"

#include "results.h"
#include "scene_hud.h"

#include <cmath>

namespace steadyxr::eval {

ResolvedEdgeMasks resolvedEdgeMasks(const std::array<Image, 2>& oneSample,
                                    const std::array<Image, 2>& resolved) {
  // Both are 8-bit renders read back as code / 255: equal codes give equal floats, and any other
  // difference is a whole step or more.
  constexpr float kHalfStep = 0.5f / 255.0f;
  ResolvedEdgeMasks m;
  for (int eye = 0; eye < 2; ++eye) {
    const Image& a = oneSample[eye];
    const Image& b = resolved[eye];
    const int w = a.width, h = a.height;
    const size_t n = size_t(w) * size_t(h);
    std::vector<uint8_t>& edge = m.edge[eye];
    edge.assign(n, 0);
    m.ring[eye].assign(n, 0);
    m.rest[eye].assign(n, 1);
    if (b.width != w || b.height != h) continue;  // no pair: every pixel is `rest`
    for (size_t i = 0; i < n; ++i) {
      for (int c = 0; c < 3; ++c) {
        if (std::fabs(a.rgb[i * 3 + c] - b.rgb[i * 3 + c]) > kHalfStep) edge[i] = 1;
      }
    }
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const size_t i = size_t(y) * w + x;
        const bool besideEdge = (x > 0 && edge[i - 1]) || (x + 1 < w && edge[i + 1]) ||
                                (y > 0 && edge[i - w]) || (y + 1 < h && edge[i + w]);
        m.ring[eye][i] = uint8_t(!edge[i] && besideEdge);
        m.rest[eye][i] = uint8_t(!edge[i] && !besideEdge);
      }
    }
  }
  return m;
}

std::string resolvedEdgesCsvRow(const std::array<Image, 2>& out, const std::array<Image, 2>& truth,
                                const ResolvedEdgeMasks& masks) {
  std::string row;
  for (const auto* mask : {&masks.edge, &masks.ring, &masks.rest}) {
    double pixels = 0;
    const double r = pooledMaskedRmse(out, truth, *mask, &pixels);
    if (!row.empty()) row += ',';
    row += fmt(r, 6);
    row += ',';
    row += std::to_string(int(pixels));
  }
  return row;
}

}  // namespace steadyxr::eval
