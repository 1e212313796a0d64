#pragma once
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

namespace stvl::test {

// The message of the std::invalid_argument that `f` throws; a test failure when it throws nothing or another type.
template <typename F>
std::string invalid_argument_of(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected std::invalid_argument, got another exception: " << e.what();
    return {};
  }
  ADD_FAILURE() << "expected std::invalid_argument, nothing was thrown";
  return {};
}

}  // namespace stvl::test
