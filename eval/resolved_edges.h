// Where an app's MSAA resolved an edge (--app-msaa, round 47): the pixels whose resolved colour differs
// from the same frame's 1-sample render are the ones a geometric edge covers in part; the ring of
// pixels beside them is covered by one surface and already exact in the app's image. A filter's error
// is reported on the three sets apart, so that a break of the promise over an MSAA app's picture shows
// where it lies (a second blur of the resolved edge lands in the ring).
#pragma once

#include "image.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace steadyxr::eval {

// Per eye, row-major masks that partition the image: `edge` (a channel differs by more than half an
// 8-bit step between the two renders), `ring` (a 4-neighbour of an edge pixel, not one itself) and
// `rest`.
struct ResolvedEdgeMasks {
  std::array<std::vector<uint8_t>, 2> edge, ring, rest;
};
ResolvedEdgeMasks resolvedEdgeMasks(const std::array<Image, 2>& oneSample,
                                    const std::array<Image, 2>& resolved);

// resolved_edges.csv (suite.cpp): after scenario, method and frame, the RMSE against the truth of both
// eyes pooled on each set (-1 where a set is empty) and the set's pixel count, both eyes.
inline constexpr const char* kResolvedEdgesCsvHeader =
    "scenario,method,frame,rmse_edge,edge_pixels,rmse_ring,ring_pixels,rmse_rest,rest_pixels";
std::string resolvedEdgesCsvRow(const std::array<Image, 2>& out, const std::array<Image, 2>& truth,
                                const ResolvedEdgeMasks& masks);

}  // namespace steadyxr::eval
