// SPDX-License-Identifier: MIT
// Internal: the message of the exception being handled, for code that must not let it escape
// (the near callback, noexcept entry points) and reports it instead.
#pragma once

#include <exception>
#include <string>

namespace rheofeed::detail {

/// The what() of the exception being handled, or a fixed text for one that is not a
/// std::exception. Call inside a catch block only.
inline std::string currentExceptionMessage() {
  try {
    throw;
  } catch (const std::exception& e) {
    return e.what();
  } catch (...) {
    return "an exception that is not a std::exception";
  }
}

}  // namespace rheofeed::detail
