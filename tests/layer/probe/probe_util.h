// Small helpers shared by the probe's sources.
#pragma once

#include "probe_xr.h"

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

namespace probe {

template <typename T>
inline T xrStruct(XrStructureType type) {
  T v{};
  v.type = type;
  return v;
}

template <typename T>
inline T vkStruct(VkStructureType type) {
  T v{};
  v.sType = type;
  return v;
}

template <typename F>
inline F xrFn(XrInstance instance, const char* name) {
  PFN_xrVoidFunction f = nullptr;
  xrGetInstanceProcAddr(instance, name, &f);
  return reinterpret_cast<F>(f);
}

inline std::string resultName(XrInstance instance, XrResult r) {
  char buf[XR_MAX_RESULT_STRING_SIZE] = {};
  if (XR_FAILED(xrResultToString(instance, r, buf)))
    std::snprintf(buf, sizeof buf, "%d", static_cast<int>(r));
  return buf;
}

inline std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::istringstream in(s);
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

inline uint16_t toHalf(float f) {  // IEEE 754 binary16, round to nearest (values here are in [0, 1])
  uint32_t x;
  std::memcpy(&x, &f, 4);
  const uint32_t sign = (x >> 16) & 0x8000u;
  const int exp = static_cast<int>((x >> 23) & 0xff) - 127 + 15;
  uint32_t mant = x & 0x7fffffu;
  if (exp <= 0) return static_cast<uint16_t>(sign);
  if (exp >= 31) return static_cast<uint16_t>(sign | 0x7c00u);
  mant += 0x1000u;  // round
  if (mant & 0x800000u) return static_cast<uint16_t>(sign | ((exp + 1) << 10));
  return static_cast<uint16_t>(sign | (exp << 10) | (mant >> 13));
}

}  // namespace probe
