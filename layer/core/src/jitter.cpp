#include "steadyxr/core/jitter.h"

#include <cmath>

namespace steadyxr::core {

float halton(uint32_t index, uint32_t base) {
  float f = 1.0f;
  float r = 0.0f;
  for (uint32_t i = index; i > 0; i /= base) {
    f /= static_cast<float>(base);
    r += f * static_cast<float>(i % base);
  }
  return r;
}

glm::vec2 haltonJitterPx(uint32_t frameIndex) {
  const uint32_t index = frameIndex % kJitterPeriod + 1;
  return {halton(index, 2) - 0.5f, halton(index, 3) - 0.5f};
}

Fov jitterFov(const Fov& fov, float dxPx, float dyPx, uint32_t width, uint32_t height) {
  if (width == 0 || height == 0) return fov;
  // Shift in tangent space: the projection is linear in tan(angle) across the image.
  const float tl = std::tan(fov.angleLeft), tr = std::tan(fov.angleRight);
  const float tu = std::tan(fov.angleUp), td = std::tan(fov.angleDown);
  const float dx = dxPx * (tr - tl) / static_cast<float>(width);
  const float dy = dyPx * (tu - td) / static_cast<float>(height);
  return {std::atan(tl + dx), std::atan(tr + dx), std::atan(tu - dy), std::atan(td - dy)};
}

bool undoesJitter(TemporalMethod method) {
  switch (method) {
    case TemporalMethod::Taa:
    case TemporalMethod::Hmtaa:
    case TemporalMethod::Vtaa:
    case TemporalMethod::Hybrid:
    case TemporalMethod::Steady:
      return true;
    case TemporalMethod::None:
    case TemporalMethod::Fxaa:
      break;
  }
  return false;
}

}  // namespace steadyxr::core
