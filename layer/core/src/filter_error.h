// How the filter's internals report a failure: the message goes to the caller's string, if any.
#pragma once

#include <string>

namespace steadyxr::core::detail {

inline void fail(std::string* error, const std::string& msg) {
  if (error) *error = msg;
}

}  // namespace steadyxr::core::detail
